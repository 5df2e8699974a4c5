#pragma once

#include <ostream>
#include <string>

#include "calib/reconstruction.h"

namespace raycarve {

enum class ModelFormat { kBinary, kText };

// "BIN" / "TXT", as COLMAP's --output_type; ModelFormatFromString throws InputError otherwise.
std::string ModelFormatToString(ModelFormat format);
ModelFormat ModelFormatFromString(const std::string& text);

// Writers of COLMAP sparse models, the inverse of model_reader.h: reading what they write gives
// back the same model exactly (text uses 17 significant digits, as COLMAP does).
void WriteCamerasBinary(const Reconstruction& reconstruction, std::ostream& stream);
void WriteImagesBinary(const Reconstruction& reconstruction, std::ostream& stream);
void WritePoints3DBinary(const Reconstruction& reconstruction, std::ostream& stream);
void WriteCamerasText(const Reconstruction& reconstruction, std::ostream& stream);
void WriteImagesText(const Reconstruction& reconstruction, std::ostream& stream);
void WritePoints3DText(const Reconstruction& reconstruction, std::ostream& stream);

// Writes cameras, images and points3D into folder `path` (created if needed). Each file is
// written under a temporary name and renamed into place, so a failed write leaves no partial
// model. Throws InputError when the folder cannot be created or a file cannot be written.
void WriteModel(const Reconstruction& reconstruction, const std::string& path, ModelFormat format);

}  // namespace raycarve
