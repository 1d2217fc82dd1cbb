#include "render/vpl_buffer.h"

namespace rtpg {

void VplBuffer::resize(std::size_t n) {
  if (info.size() != n) {
    position.assign(n, glm::vec4(0.0f));
    normal_radiance.assign(n, glm::uvec4(0u));
    strategy_pdf.assign(n, 0.0f);
  }
  info.assign(n, 0u);
}

}  // namespace rtpg
