// Structural check of PLY files before assimp reads them: assimp 5.2.5 hangs on a PLY header
// without end_header and crashes on a truncated binary body, so such files must never reach it.
#pragma once

#include <string>

namespace rtpg {

// Throws InputError(path, problem (context)) unless the header is well formed and the body
// holds every element the header announces, with face indices inside the vertex range and
// every float or double value finite and inside the float range.
void check_ply(const std::string& path, const std::string& context);

}  // namespace rtpg
