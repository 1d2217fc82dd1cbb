// Writes a whole text file or nothing: a temporary in the same folder, then rename.
#pragma once

#include <string>

namespace rtpg {

// Throws InputError(path, problem) when the file cannot be written.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace rtpg
