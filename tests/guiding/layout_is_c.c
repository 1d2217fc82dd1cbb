/* include/rtpg/guiding_layout.h is plain C: this file compiles it as C99 with warnings as
 * errors (tests/guiding/CMakeLists.txt) and checks the sizes the layout states. */
#include <stdio.h>

#include "rtpg/guiding_layout.h"

#define PG_SUM_BYTES(name, type, bytes) +(bytes)

int main(void) {
  int failed = 0;
  if (sizeof(pg_kernel_settings) != 25 * 4) {
    printf("pg_kernel_settings: %u bytes, expected 100\n", (unsigned)sizeof(pg_kernel_settings));
    failed = 1;
  }
  if (sizeof(pg_gbuffer_cameras) != 34 * 4) {
    printf("pg_gbuffer_cameras: %u bytes, expected 136\n", (unsigned)sizeof(pg_gbuffer_cameras));
    failed = 1;
  }
  if (0 PG_GBUFFER_CHANNELS(PG_SUM_BYTES) != 5 * 16 + 4 + 4 + 8 ||
      0 PG_PACKED_GBUFFER_CHANNELS(PG_SUM_BYTES) != 16 + 8 ||
      0 PG_VPL_CHANNELS(PG_SUM_BYTES) != 2 * 16 ||
      0 PG_SAMPLE_CHANNELS(PG_SUM_BYTES) != 16 + 4 + 16 + 8 ||
      0 PG_STATE_CHANNELS(PG_SUM_BYTES) != 4 * PG_STATE_FLOATS_PER_PIXEL) {
    printf("channel bytes differ from the documented layout\n");
    failed = 1;
  }
  if (PG_VPL_STRATEGY(PG_VPL_VALID | (PG_STRATEGY_GUIDE << PG_VPL_STRATEGY_SHIFT)) !=
      PG_STRATEGY_GUIDE) {
    printf("PG_VPL_STRATEGY does not invert the packing\n");
    failed = 1;
  }
  printf("%s\n", failed ? "layout check failed" : "layout check passed");
  return failed;
}
