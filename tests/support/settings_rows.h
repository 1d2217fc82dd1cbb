// A settings struct with one row of its table (include/rtpg/setting_info.h) changed alone, for
// the tests that check what each row reaches.
#pragma once

#include <optional>
#include <string>

namespace rtpg::test {

// Settings{} with `row` set to a valid value away from its default, or nothing where no
// candidate (twice, half, one more or one less than the default, the range's ends) is valid.
// `valid(settings)` says whether the whole struct is; the work-group size is per device in both
// directions or neither, so local_x and local_y change together.
template <class Settings, class Row, class Valid>
std::optional<Settings> with_row_changed(const Row& row, Valid valid) {
  const double d = row.get(Settings{});
  for (const double v : {2.0 * d, 0.5 * d, d + 1.0, d - 1.0, row.min, row.max}) {
    Settings s;
    if (!row.in_range(v) || v == d) continue;
    row.set(s, v);
    if (row.get(s) == d) continue;
    if (std::string(row.name) == "local_x") s.local_y = s.local_x;
    if (std::string(row.name) == "local_y") s.local_x = s.local_y;
    if (valid(s)) return s;
  }
  return std::nullopt;
}

}  // namespace rtpg::test
