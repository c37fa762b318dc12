#pragma once
// Files embedded at build time by cmake/EmbedResource.cmake (generated .cpp in
// the build folder; libc3po/web/CMakeLists.txt lists them).
#include <string>

namespace c3po::resources {

// three.js r111 ES module from Debian's libjs-three
// (/usr/share/javascript/three/three.module.js; third_party_notes/three.js.md).
std::string ThreeJsModule();
std::string ThreeJsLicense();       // three_license.js: the MIT notice the Debian build lacks
// libc3po/web/resources/: the pages' static parts.
std::string AnnotationPageCss();    // annotation_page.css (inside <style>)
std::string AnnotationPageBody();   // annotation_page_body.html (the layout after <body>)
std::string AnnotationPageJs();     // annotation_page.js (inside <script type="module">)
std::string ReportCss();            // report.css
std::string ReportViewJs();         // report_view.js: the 3D view of the report

}  // namespace c3po::resources
