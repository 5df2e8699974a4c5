#pragma once
// report.html: one page with a carve's summary, its pictures, its convergence plot and a 3D view
// of the mesh that works when opened from disk (file://) with no network: the viewer's scripts
// (three.js, embedded in raycarve at build time) and the mesh (mesh.glb, base64) are in the page.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "carve/carver.h"

namespace raycarve {

// The largest mesh.glb the page embeds (base64 grows it by a third; browsers give up on pages
// of a few hundred MB): 256 MiB.
constexpr uint64_t kMaxEmbeddedGlbBytes = uint64_t{256} << 20;

struct ReportPageContent {
  std::string title;    // the page's heading (e.g. the model's path)
  std::string summary;  // the summary as the command prints it (shown as preformatted text)
  std::string preview_image;  // a picture beside the page (relative name); empty: none
  std::vector<CurveSample> convergence;  // voxels carved against seconds; empty: no plot
  std::vector<uint8_t> glb;  // the mesh as glTF binary; empty: no 3D view
  std::string glb_name;      // its file beside the page, named in the view's caption
  // When the mesh's file is too large to embed (kMaxEmbeddedGlbBytes): its size, and `glb` is
  // left empty; the page names the file instead of showing it.
  uint64_t glb_bytes_not_embedded = 0;
  // Where the 3D view starts: the world's "up" and the direction from the model towards its
  // eye (the photos' mean up and mean camera direction); zero: +z up, seen from an oblique corner.
  Eigen::Vector3d view_up = Eigen::Vector3d::Zero();
  Eigen::Vector3d view_from = Eigen::Vector3d::Zero();
};

// The page's HTML. The 3D view reports its state in the element #view-status (data-state
// "loading", "ready" or "error") and any console error in #console-errors, so that a headless
// browser's DOM dump says whether it worked; `report.html#view` shows the view alone, filling the
// window.
std::string ReportPageHtml(const ReportPageContent& content);

// Whether this raycarve has the 3D view's scripts built in (cmake/embed_viewer.cmake).
bool ReportPageHasViewer();

// The viewer's scripts (generated at build time; empty when they were not installed).
const std::string& ViewerScript();

// Standard base64 (RFC 4648, with padding).
std::string Base64(const std::vector<uint8_t>& bytes);

// `text` with &, <, > and " escaped for HTML.
std::string HtmlEscape(const std::string& text);

}  // namespace raycarve
