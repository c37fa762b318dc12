#pragma once
// Static parts of the evaluation report page (report.cpp fills in the data).
#include <string>

namespace c3po::report_page {

std::string Style();        // the <style> element
// The module script of the 3D view: reads #c3po-views (JSON) and #c3po-three
// (three.js source, imported through a Blob URL), sets window.c3poReport and
// document.body.dataset.ready.
std::string ViewScript();

}  // namespace c3po::report_page
