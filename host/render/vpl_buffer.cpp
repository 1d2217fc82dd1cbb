#include "render/vpl_buffer.h"

namespace rtpg {

void VplBuffer::resize(std::size_t n) {
  if (info.size() != n) {
    position.assign(n, glm::vec4(0.0f));
    normal_radiance.assign(n, glm::uvec4(0u));
    strategy_pdf.assign(n, 0.0f);
  }
  if (for_bus && packed.distance.size() != n) {
#define RTPG_ASSIGN(name, type, bytes) packed.name.assign(n, shared::type(0));
    PG_PACKED_VPL_CHANNELS(RTPG_ASSIGN)
#undef RTPG_ASSIGN
  }
  info.assign(n, 0u);
}

}  // namespace rtpg
