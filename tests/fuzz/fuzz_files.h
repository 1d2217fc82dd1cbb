// What every fuzz target shares (tests/fuzz/README.md): the input goes into a file in a
// folder of this process, next to small valid companions (an OBJ, its MTL, a PNG texture, a
// PLY), so that paths named by a fuzzed file can resolve and reach deeper code. A target
// passes an input when the loader returns or throws InputError (a clear error for the user);
// any other exception, a crash, a sanitizer report or a hang is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace rtpg::fuzz {

// The folder (created with its companions on the first call): m.obj, m.mtl, t.png, p.ply.
const std::string& work_folder();

// Writes the input to `name` inside work_folder() and returns the file's path.
std::string write_input(const std::uint8_t* data, std::size_t size, const char* name);

}  // namespace rtpg::fuzz
