#include "render/host_transfer.h"

#include <cstdlib>

#include "rtpg/errors.h"

namespace rtpg {

HostTransfer parse_host_transfer(const std::string& name) {
  if (name == "auto") return HostTransfer::automatic;
  if (name == "in-place") return HostTransfer::in_place;
  if (name == "pinned") return HostTransfer::pinned;
  if (name == "pageable") return HostTransfer::pageable;
  if (name == "packed") return HostTransfer::packed;
  throw GuiderError("host transfer '" + name +
                    "' is none of auto, in-place, pinned, packed, pageable");
}

const char* host_transfer_name(HostTransfer transfer) {
  switch (transfer) {
    case HostTransfer::automatic:
      return "auto";
    case HostTransfer::in_place:
      return "in-place";
    case HostTransfer::pinned:
      return "pinned";
    case HostTransfer::pageable:
      return "pageable";
    case HostTransfer::packed:
      return "packed";
  }
  return "?";
}

HostTransfer resolve_host_transfer(HostTransfer transfer, bool host_unified_memory) {
  if (transfer == HostTransfer::automatic) {
    if (const char* env = std::getenv("RTPG_HOST_TRANSFER"); env && *env) {
      try {
        transfer = parse_host_transfer(env);
      } catch (const GuiderError& e) {
        throw GuiderError(std::string("RTPG_HOST_TRANSFER: ") + e.what());
      }
    }
  }
  if (transfer == HostTransfer::automatic)
    transfer = host_unified_memory ? HostTransfer::in_place : HostTransfer::packed;
  return transfer;
}

}  // namespace rtpg
