// Text checks of Wavefront OBJ files and their MTL libraries before assimp reads them. assimp
// is silent where a wrong scene would render without a word: it reads "nan", "inf" and 1e39 as
// vertex coordinates, a ten-million-digit number as 0, an MTL's Kd nan or Ns -1 as given, and a
// missing .mtl as "every surface grey". Ranges: docs/robustness.md, "Input validation".
#pragma once

#include <cstddef>
#include <string>

namespace rtpg {

// Throws InputError naming the file, the line and (in an MTL) the material unless every
// number of the vertex statements (v, vn, vt, vp) and of the MTL statements is finite, fits a
// float, has at most kMaxNumberLength characters and lies in its statement's range, and every
// mtllib names a file that exists. `context` says where the file was named (a scene key).
// Without with_materials (the scene replaces them) a missing MTL library is no error, but one
// that exists is checked all the same: assimp parses it whatever the scene does.
void check_obj(const std::string& path, const std::string& context, bool with_materials);

// Longer numeric tokens are refused: no float needs more (9 significant digits, a sign, a
// point and an exponent fit in 16), and a megabyte-long one is a broken or hostile file.
constexpr std::size_t kMaxNumberLength = 64;

}  // namespace rtpg
