// GuidingConfig -> the plain struct the kernels (and host code using the shared math) read.
#pragma once

#include "rtpg/guider.h"
#include "shared/pmm.h"

namespace rtpg {

shared::pg_guiding_params make_guiding_params(const GuidingConfig& config);

}  // namespace rtpg
