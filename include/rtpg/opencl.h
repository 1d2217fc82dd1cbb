// The one place that includes the Khronos C++ bindings. From /usr/include the compiler
// treats them as a system header and stays quiet, but a copy found through -I trips
// -Wmissing-field-initializers (the 2023.02 headers), and older releases -Wpedantic,
// -Wshadow and -Wignored-attributes; the project builds with -Werror, so warnings from code
// we do not own are silenced here and nowhere else.
#pragma once

// CMake sets these for every target that links rtpg_cl; the defaults keep a stray include
// from a target that does not (a tool, an IDE indexer) on the same OpenCL 1.2 API.
#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_ENABLE_EXCEPTIONS
#define CL_HPP_ENABLE_EXCEPTIONS
#endif

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wignored-attributes"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <CL/opencl.hpp>
#pragma GCC diagnostic pop
