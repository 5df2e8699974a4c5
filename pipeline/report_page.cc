#include "pipeline/report_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "export/line_plot.h"

namespace raycarve {
namespace {

constexpr const char* kStyle = R"css(
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1200px; color: #222; padding: 0 1em; }
h1 { font-size: 1.4em; word-break: break-all; }
h2 { font-size: 1.15em; margin-top: 1.6em; }
pre { background: #f4f4f4; padding: 0.8em; overflow-x: auto; font-size: 0.85em; line-height: 1.3; }
#view { width: 100%; height: 560px; display: block; background: #20242a; touch-action: none; }
#view-status { font-size: 0.85em; color: #555; }
#console-errors:empty { display: none; }
#console-errors { color: #a00; }
img { max-width: 100%; }
svg text { font-family: sans-serif; font-size: 12px; }
body.view-only { margin: 0; padding: 0; max-width: none; overflow: hidden; }
body.view-only > :not(#view-section) { display: none; }
body.view-only #view-section > :not(#view) { display: none; }
body.view-only #view { width: 100vw; height: 100vh; }
)css";

// The 3D view: the glTF parsed from the page, drawn unlit (the texture and colours come from the
// photos, their light already in them), framed on its bounding box, turned with the mouse.
constexpr const char* kViewerCode = R"js(
(function () {
  const status = document.getElementById('view-status');
  const errors = document.getElementById('console-errors');
  function note(text) { errors.textContent += text + '\n'; }
  function fail(text) {
    status.dataset.state = 'error';
    status.textContent = '3D view failed: ' + text;
    note(text);
  }
  const consoleError = console.error.bind(console);
  console.error = function () {
    note(Array.prototype.join.call(arguments, ' '));
    consoleError.apply(null, arguments);
  };
  window.addEventListener('error', function (e) { fail(e.message); });
  if (location.hash === '#view') document.body.classList.add('view-only');
  if (typeof THREE === 'undefined') { fail('three.js is not in this page'); return; }
  try {
    const text = atob(document.getElementById('model-data').textContent.trim());
    const bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
    const canvas = document.getElementById('view');
    const renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
    renderer.outputEncoding = THREE.sRGBEncoding;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0x20242a);
    const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
    let controls = null;
    function draw() {
      const width = canvas.clientWidth, height = canvas.clientHeight;
      if (canvas.width !== Math.round(width * renderer.getPixelRatio()) ||
          canvas.height !== Math.round(height * renderer.getPixelRatio())) {
        renderer.setSize(width, height, false);
        camera.aspect = width / Math.max(1, height);
        camera.updateProjectionMatrix();
      }
      renderer.render(scene, camera);
    }
    window.addEventListener('resize', draw);
    new THREE.GLTFLoader().parse(bytes.buffer, '', function (gltf) {
      let triangles = 0;
      gltf.scene.traverse(function (node) {
        if (!node.isMesh) return;
        const old = node.material;
        node.material = new THREE.MeshBasicMaterial({
          map: old.map || null,
          vertexColors: !old.map && node.geometry.hasAttribute('color'),
          side: THREE.DoubleSide
        });
        const index = node.geometry.getIndex();
        triangles += (index ? index.count : node.geometry.getAttribute('position').count) / 3;
      });
      scene.add(gltf.scene);
      const box = new THREE.Box3().setFromObject(gltf.scene);
      const centre = box.getCenter(new THREE.Vector3());
      const radius = Math.max(1e-6, box.getSize(new THREE.Vector3()).length() / 2);
      // Up and the first viewpoint as the photos had them (set by raycarve in RAYCARVE_VIEW).
      const start = window.RAYCARVE_VIEW || {};
      const up = new THREE.Vector3().fromArray(start.up || [0, 0, 1]);
      const from = new THREE.Vector3().fromArray(start.from || [1, -1, 0.8]);
      if (up.lengthSq() === 0) up.set(0, 0, 1);
      if (from.lengthSq() === 0) from.set(1, -1, 0.8);
      const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
      camera.up.copy(up.normalize());
      camera.position.copy(centre).add(from.normalize().multiplyScalar(distance));
      camera.near = distance / 100;
      camera.far = distance * 10;
      camera.updateProjectionMatrix();
      controls = new THREE.OrbitControls(camera, canvas);
      controls.target.copy(centre);
      controls.update();
      controls.addEventListener('change', draw);
      draw();
      status.dataset.state = 'ready';
      status.textContent = Math.round(triangles) + ' triangles: drag to turn, scroll to zoom, right-drag to move';
    }, function (error) { fail(error && error.message ? error.message : String(error)); });
  } catch (e) {
    fail(e.message);
  }
})();
)js";

// Voxels carved against seconds, as an SVG line on axes from zero with round ticks.
std::string ConvergenceSvg(const std::vector<CurveSample>& curve) {
  const int width = 720, height = 300, left = 80, right = 20, top = 15, bottom = 45;
  double max_seconds = 0.0, max_carved = 0.0;
  for (const CurveSample& sample : curve) {
    max_seconds = std::max(max_seconds, sample.seconds);
    max_carved = std::max(max_carved, static_cast<double>(sample.carved));
  }
  const double x_step = exporter::TickSpacing(max_seconds, 6);
  const double y_step = exporter::TickSpacing(max_carved, 5);
  const double x_max = std::max(x_step, std::ceil(max_seconds / x_step) * x_step);
  const double y_max = std::max(y_step, std::ceil(max_carved / y_step) * y_step);
  const auto x_of = [&](double s) { return left + (width - left - right) * s / x_max; };
  const auto y_of = [&](double c) { return height - bottom - (height - top - bottom) * c / y_max; };
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" role=\"img\" aria-label=\"voxels carved against seconds\">\n";
  char number[64];
  for (double s = 0.0; s <= x_max + 1e-9 * x_max; s += x_step) {
    std::snprintf(number, sizeof(number), "%g", s);
    svg << "<line x1=\"" << x_of(s) << "\" y1=\"" << top << "\" x2=\"" << x_of(s) << "\" y2=\""
        << height - bottom << "\" stroke=\"#ddd\"/><text x=\"" << x_of(s) << "\" y=\""
        << height - bottom + 16 << "\" text-anchor=\"middle\">" << number << "</text>\n";
  }
  for (double c = 0.0; c <= y_max + 1e-9 * y_max; c += y_step) {
    std::snprintf(number, sizeof(number), "%g", c);
    svg << "<line x1=\"" << left << "\" y1=\"" << y_of(c) << "\" x2=\"" << width - right
        << "\" y2=\"" << y_of(c) << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\""
        << y_of(c) + 4 << "\" text-anchor=\"end\">" << number << "</text>\n";
  }
  svg << "<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"2\" points=\"";
  for (const CurveSample& sample : curve) {
    svg << x_of(sample.seconds) << "," << y_of(static_cast<double>(sample.carved)) << " ";
  }
  svg << "\"/>\n<text x=\"" << (left + width - right) / 2 << "\" y=\"" << height - 8
      << "\" text-anchor=\"middle\">seconds</text>\n<text x=\"14\" y=\"" << (top + height - bottom) / 2
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 14 " << (top + height - bottom) / 2
      << ")\">voxels carved</text>\n</svg>\n";
  return svg.str();
}

// A script's text safe inside <script>...</script>: "</script" written as "<\/script" (the same
// in a JavaScript string or regular expression).
std::string ScriptText(const std::string& script) {
  std::string out;
  size_t from = 0;
  for (size_t at = script.find("</script"); at != std::string::npos; at = script.find("</script", from)) {
    out.append(script, from, at - from).append("<\\/script");
    from = at + 8;
  }
  return out.append(script, from, std::string::npos);
}

std::string JsVector(const Eigen::Vector3d& v) {
  char text[96];
  std::snprintf(text, sizeof(text), "[%.6g, %.6g, %.6g]", v.x(), v.y(), v.z());
  return text;
}

}  // namespace

std::string Base64(const std::vector<uint8_t>& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t{bytes[i]} << 16) | (uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += kDigits[(v >> 6) & 63];
    out += kDigits[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const uint32_t v = (uint32_t{bytes[i]} << 16) | (two ? uint32_t{bytes[i + 1]} << 8 : 0u);
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += two ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

bool ReportPageHasViewer() { return !ViewerScript().empty(); }

std::string ReportPageHtml(const ReportPageContent& content) {
  std::ostringstream html;
  html << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       << "<title>raycarve: " << HtmlEscape(content.title) << "</title>\n<style>" << kStyle
       << "</style>\n</head>\n<body>\n<h1>raycarve: " << HtmlEscape(content.title) << "</h1>\n";
  html << "<section id=\"view-section\">\n<h2>The model</h2>\n";
  if (content.glb_bytes_not_embedded > 0) {
    char size[32];
    std::snprintf(size, sizeof(size), "%.0f MB", content.glb_bytes_not_embedded / 1e6);
    html << "<p>" << HtmlEscape(content.glb_name) << " (" << size << ") is too large to show in "
         << "this page: open it in a viewer such as Blender or MeshLab, or carve at a coarser "
            "--resolution.</p>\n";
  } else if (content.glb.empty()) {
    html << "<p>No mesh to show (the carve kept nothing, or wrote its voxels' faces only).</p>\n";
  } else if (!ReportPageHasViewer()) {
    html << "<p>This raycarve was built without the 3D view's scripts (scripts/setup.sh installs "
            "them with npm). Open " << HtmlEscape(content.glb_name)
         << " in a viewer such as Blender or MeshLab.</p>\n";
  } else {
    html << "<canvas id=\"view\"></canvas>\n<p id=\"view-status\" data-state=\"loading\">loading "
         << HtmlEscape(content.glb_name) << " ...</p>\n";
  }
  html << "<pre id=\"console-errors\"></pre>\n</section>\n";
  html << "<section>\n<h2>Summary</h2>\n<pre>" << HtmlEscape(content.summary) << "</pre>\n</section>\n";
  if (!content.preview_image.empty()) {
    html << "<section>\n<h2>Photos and the model from their cameras</h2>\n<p>Each row: a photo, "
            "then the mesh drawn from that photo's camera.</p>\n<img src=\""
         << HtmlEscape(content.preview_image) << "\" alt=\"photos beside renders of the model\">\n"
         << "</section>\n";
  }
  if (content.convergence.size() >= 2) {
    html << "<section>\n<h2>Convergence</h2>\n<p>Voxels carved by colour against the carve's "
            "seconds (convergence.csv).</p>\n"
         << ConvergenceSvg(content.convergence) << "</section>\n";
  }
  if (!content.glb.empty() && ReportPageHasViewer()) {
    html << "<script id=\"model-data\" type=\"application/octet-stream\">" << Base64(content.glb)
         << "</script>\n<script>" << ScriptText(ViewerScript()) << "</script>\n<script>"
         << "window.RAYCARVE_VIEW = {up: " << JsVector(content.view_up)
         << ", from: " << JsVector(content.view_from) << "};\n" << kViewerCode
         << "</script>\n";
  }
  html << "</body>\n</html>\n";
  return html.str();
}

}  // namespace raycarve
