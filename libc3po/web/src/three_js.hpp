#pragma once
// three.js as the pages embed it. Private to libc3po/web.
#include <string>

namespace c3po::web {

// The module of Debian's libjs-three with its MIT licence notice in front
// (resources/three_license.js; the Debian build has none), checked to contain
// no "</script" (it goes inside a <script type="text/plain"> element).
std::string ThreeJsForPage();

}  // namespace c3po::web
