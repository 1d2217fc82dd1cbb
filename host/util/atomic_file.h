// Whole files or nothing: every output is written to a temporary in its own folder, then renamed
// into place.
#pragma once

#include <string>

namespace rtpg {

// "dir/.name.tmp-<pid>.ext": the same folder (so the rename is atomic) and the same extension
// (OpenImageIO picks the format from it).
std::string temporary_path_for(const std::string& path);

// Throws InputError(path, problem) when no file can be created beside `path` (a folder that
// refuses new files), by creating and removing its temporary: run before any work, so that a run
// does not write one output and then fail on the next.
void check_can_create(const std::string& path);

// Throws InputError(path, problem) when the file cannot be written.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace rtpg
