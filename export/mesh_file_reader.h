#pragma once
// Reading a textured mesh that another program (or raycarve) wrote, as glTF 2.0 or Wavefront OBJ,
// so that holdout can score it and render can draw it. tinygltf and tinyobjloader stay inside
// the .cc file.

#include <string>

#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Reads a glTF 2.0 file (.glb, or .gltf with its buffers and images beside it) as one triangle
// mesh in the file's world frame: every TRIANGLES primitive of every mesh node of the default
// scene (the first scene when none is set; every root node when there is no scene), placed by
// its node's transforms (matrix, or translation, rotation and scale, down the node tree).
// Per vertex: the position, the normal where given (else computed from the triangles), the
// colour (COLOR_0, linear as glTF has it, made sRGB bytes) where given. Primitives whose
// material has a base colour texture with TEXCOORD_0 keep it: the textures are put side by side
// in one atlas (each texture's coordinates wrapped into 0-1 per triangle and rescaled into its
// place); triangles without one sample a white texel, so the mesh is textured when any primitive
// is. Throws InputError naming the file and what is wrong (not glTF, an accessor reaching past
// its buffer, an index past the vertices, no triangles, an image that does not decode).
TriangleMesh ReadGltf(const std::string& path);

// Reads a Wavefront OBJ mesh (tinyobjloader; polygons fanned into triangles) with the materials
// of its .mtl: the diffuse texture maps (map_Kd, beside the OBJ or as the MTL names them) side by
// side in one atlas as ReadGltf does, with the OBJ's texture coordinates (v up) turned to v
// down; vertex colours where the file has them; normals computed from the triangles. Throws
// InputError naming the file (an index past the vertices, no triangles, a texture that cannot be
// read or announces more than 8192 x 8192 texels).
TriangleMesh ReadObj(const std::string& path);

// Whether `path` names a glTF file (extension .glb or .gltf, any case).
bool IsGltfPath(const std::string& path);
// Whether `path` names an OBJ file (extension .obj, any case).
bool IsObjPath(const std::string& path);

// The model at `path` by its extension: .glb or .gltf (ReadGltf), .obj (ReadObj), else PLY
// (ReadMeshOrCloudPly: a mesh, or a cloud with no triangles).
TriangleMesh ReadModelFile(const std::string& path);

}  // namespace exporter
}  // namespace raycarve
