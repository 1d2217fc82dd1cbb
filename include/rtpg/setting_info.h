// One row of a settings table: a numeric field of a settings struct with its name, meaning and
// valid range. Guiding (include/rtpg/guiding_settings.h) and the denoiser
// (host/denoise/svgf_settings.h) describe their settings this way, so the command line builds
// its flags, validation names the setting and the stats JSON records every row from one table.
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace rtpg {

// A number as the tables print it: "inf" for an unbounded end, else the shortest form.
inline std::string setting_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream out;
  out << v;
  return out.str();
}

// Exactly one of float_field and int_field is set.
template <class Settings>
struct SettingInfo {
  const char* name;
  const char* help;
  double min, max;
  bool min_exclusive, max_exclusive;
  float Settings::*float_field;
  int Settings::*int_field;

  // A float field; an unbounded range still excludes infinity: every setting is finite.
  static SettingInfo real(const char* name, float Settings::*field, double min, double max,
                          bool min_exclusive, bool max_exclusive, const char* help) {
    return {name, help, min, max, min_exclusive, max_exclusive || std::isinf(max), field, nullptr};
  }
  static SettingInfo integer(const char* name, int Settings::*field, double min, double max,
                             const char* help) {
    return {name, help, min, max, false, false, nullptr, field};
  }

  double get(const Settings& s) const {
    return float_field ? static_cast<double>(s.*float_field) : static_cast<double>(s.*int_field);
  }
  // Rounds for an integer field.
  void set(Settings& s, double value) const {
    if (float_field) {
      s.*float_field = static_cast<float>(value);
    } else {
      s.*int_field = static_cast<int>(std::lround(value));
    }
  }
  bool in_range(double v) const {
    const bool above = min_exclusive ? v > min : v >= min;
    const bool below = max_exclusive ? v < max : v <= max;
    return above && below;  // false for NaN
  }
  // "[0, 1)", "(0, inf)", ...
  std::string range_text() const {
    return std::string(min_exclusive ? "(" : "[") + setting_number(min) + ", " +
           setting_number(max) + (max_exclusive ? ")" : "]");
  }
};

}  // namespace rtpg
