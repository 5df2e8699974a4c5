#pragma once

#include <istream>
#include <string>

#include "calib/reconstruction.h"

namespace raycarve {

// Readers of COLMAP sparse models (format: ../shared/notes/colmap_formats.md; COLMAP 3.8).
//
// Each reader has a stream form, fed by tests from strings, and `source` names the stream in
// error messages (usually the file path). They fill one part of `reconstruction` and throw
// InputError naming the source, the record and the field on: truncated or trailing data, a count
// that the remaining bytes cannot hold, a duplicate id, an unknown or unsupported camera model,
// a malformed number. Binary files are little-endian. Cross-references between the three files
// are checked by ValidateReconstruction (ReadModel calls it).
void ReadCamerasBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction);
void ReadImagesBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction);
void ReadPoints3DBinary(std::istream& stream, const std::string& source, Reconstruction* reconstruction);
void ReadCamerasText(std::istream& stream, const std::string& source, Reconstruction* reconstruction);
void ReadImagesText(std::istream& stream, const std::string& source, Reconstruction* reconstruction);
void ReadPoints3DText(std::istream& stream, const std::string& source, Reconstruction* reconstruction);

// Reads the model in folder `path`: for each of cameras, images and points3D the `.bin` file when
// present, else the `.txt` one. Other files in the folder (COLMAP >= 3.12's rigs and frames,
// project.ini) are ignored. Throws InputError when the folder or a file is missing or unreadable,
// or the model is inconsistent (ValidateReconstruction). An empty model is returned as such.
Reconstruction ReadModel(const std::string& path);

}  // namespace raycarve
