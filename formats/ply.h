#pragma once
// PLY (binary little-endian): the cloud's points that exist, as float x y z
// in metres and, with colour, uchar red green blue. Unorganized, as mesh and
// point tools (MeshLab, CloudCompare, Open3D) expect.
#include <string>

#include "apply/depth_corrector.h"

namespace speckle::formats {

std::string PlyFile(const apply::OrganizedCloud& cloud, const std::string& comment);

}  // namespace speckle::formats
