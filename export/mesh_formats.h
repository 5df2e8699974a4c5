#pragma once
// The mesh in the formats other programs load: glTF 2.0 binary (Blender, web viewers, game
// engines) and, textured, OBJ with its material and atlas. tinygltf stays inside the .cc file.

#include <string>

#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Writes `<stem>.obj`, `<stem>.mtl` and `<stem>_texture.png` beside each other (`obj_path` ends
// in .obj): positions, normals, the corners' texture coordinates, one material whose diffuse map
// is the atlas. Each file under a temporary name and renamed; throws InputError naming the file
// on failure. The mesh must be textured.
void WriteTexturedObj(const TriangleMesh& mesh, const std::string& obj_path);

// Writes the mesh as glTF 2.0 binary: positions, normals, and the texture (PNG, embedded) with
// its coordinates when the mesh is textured, else the vertex colours (COLOR_0). Temporary name
// and rename; throws InputError naming the file on failure.
void WriteGlb(const TriangleMesh& mesh, const std::string& path);

// Writes <folder>/mesh.glb and, when the mesh is textured, <folder>/mesh.obj, mesh.mtl and
// mesh_texture.png (WriteGlb and WriteTexturedObj), splitting the corners and encoding the atlas
// once for both.
void WriteMeshFormats(const TriangleMesh& mesh, const std::string& folder);

}  // namespace exporter
}  // namespace raycarve
