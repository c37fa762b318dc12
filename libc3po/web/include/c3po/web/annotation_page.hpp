#pragma once
// The self-contained annotation page (`c3po annotate --html view.html`): one
// HTML file with three.js embedded, the mesh, the keypoints (index + name), the
// indicator sets in colour; clicking the surface adds a keypoint, clicking a
// keypoint removes it (sets containing it are dropped, the others remapped),
// and a button downloads the object JSON (same schema as WriteObjectSpec).
// No network access when opened.
//
// Test hooks in the page: window.c3poState = {keypoints, keypoint_names,
// indicator_sets}, window.c3poObjectJson() (the JSON the button downloads),
// window.c3poDebug.{keypointPixel(i), meshPixel()} (page pixels for scripted
// clicks) and document.body.dataset.ready = "1" once loaded.
#include <string>

#include "c3po/geometry/mesh.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

// The page's HTML. `object_json_path` is where the object JSON is (or will
// be) written: the page's download names the mesh relative to that folder,
// like WriteObjectSpec does.
std::string AnnotationPageHtml(const ObjectSpec& spec, const Mesh& mesh,
                               const std::string& object_json_path);

// Writes AnnotationPageHtml atomically to `html_path`.
void WriteAnnotationPage(const ObjectSpec& spec, const Mesh& mesh,
                         const std::string& object_json_path, const std::string& html_path);

}  // namespace c3po
