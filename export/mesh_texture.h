#pragma once
// A texture atlas for a mesh from the photos: each triangle takes its colours from the photo that
// sees it best, neighbours share photos where they can, and the pieces of photo are packed into
// one image. Its files: export/mesh_formats.h.

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

struct MeshTextureOptions {
  // A triangle takes the photo its neighbours take when that photo sees all its corners with at
  // least this share of its best photo's projected area; this many passes. Fewer, larger charts
  // mean fewer seams.
  double neighbour_share = 0.5;
  int relabel_passes = 3;
  // Photo pixels kept around each chart, so that sampling at its edge stays inside it.
  int padding = 2;
  // The atlas's longer side at most; the charts are scaled down when they would not fit.
  int max_atlas_side = 8192;
  // Each chart's colours scaled (per channel, within [1/1.4, 1.4]) so that its photo's colours at
  // the chart's vertices match the vertices' colours, which all the photos that see them agreed
  // on: the photos' exposures differ and the seams between charts would show it.
  bool level_colours = true;
  // Each texel the mean of every candidate photo's colour at its point (weighted by the area the
  // triangle covers in each, outliers left out) rather than its chart's photo alone: the
  // photos' view-dependent light and the geometry's error average out as in the vertex colours,
  // at the photos' resolution. Levelling is then not needed.
  bool blend_views = true;
  // Threads making the charts' pieces (< 1: one per core); the atlas does not depend on it.
  int num_threads = 1;
  bool IsValid(std::string* reason) const;
};

struct MeshTextureSummary {
  int64_t triangles = 0;
  int64_t textured = 0;  // from the photos; the rest take their vertices' colours
  int64_t charts = 0;
  int64_t relabelled = 0;  // triangles that took their neighbours' photo
  int atlas_width = 0;
  int atlas_height = 0;
  double scale = 1.0;  // photo pixels to atlas pixels (1 unless the atlas had to shrink)
  // No texture: the atlas would pass max_atlas_side even scaled down (`needed_width` x
  // `needed_height` at a tenth or less of the photos' resolution); the mesh keeps its vertex
  // colours and atlas_width is 0.
  bool too_large = false;
  int needed_width = 0;
  int needed_height = 0;
  double seconds = 0.0;
  // How the charts join (MeasureTextureSeams).
  int64_t seam_edges = 0;
  double seam_step = 0.0;
  double inner_step = 0.0;
  std::string Summary() const;
};

// How well a textured mesh's charts join. Across every edge two triangles share, the texture is
// sampled one texel inside each of them at a quarter, half and three quarters along the edge, and
// the two colours compared (RGB distance over sqrt(3), 0-255): `seam_step` is the mean over edges
// whose triangles lie in different charts (their corners' texture coordinates differ), `inner_step`
// over edges inside one chart, the texture's own change over two texels. A seam that shows has a
// step well above the inner one. Zeros when the mesh has no texture or no such edge.
struct TextureSeams {
  int64_t seam_edges = 0;
  int64_t inner_edges = 0;
  double seam_step = 0.0;
  double inner_step = 0.0;
};
TextureSeams MeasureTextureSeams(const TriangleMesh& mesh);

// Sets mesh->corner_uvs and mesh->texture. `seen_by` gives per vertex the views (indices into
// `views`) that see it (ColourMeshFromPhotos); a triangle's candidate photos see all three of its
// corners, inside the photo and facing the camera, and it takes the one where it covers the most
// pixels (resolution and obliqueness in one figure). Triangles no photo sees whole take their
// vertices' colours (mesh->colours), blended over a small cell each. Needs mesh->colours.
MeshTextureSummary TextureMeshFromPhotos(const std::vector<CalibratedView>& views,
                                         const std::vector<std::vector<uint32_t>>& seen_by,
                                         const MeshTextureOptions& options, TriangleMesh* mesh);

}  // namespace exporter
}  // namespace raycarve
