/* Per-pixel flags of the G-buffer, shared by the host renderer and the guiding kernels.
 * They say which pixels guiding must skip (paper, section 5: sky, emitters, transmission,
 * roughness near zero) so the kernels do no work there. */
#ifndef RTPG_SHARED_GBUFFER_H
#define RTPG_SHARED_GBUFFER_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

#define PG_GBUF_SKY 1u          /* camera ray escaped: no surface */
#define PG_GBUF_EMITTER 2u      /* surface emits towards the camera */
#define PG_GBUF_DELTA 4u        /* roughness at or below the delta threshold */
#define PG_GBUF_TRANSMISSIVE 8u /* transmissive material */

PG_NAMESPACE_END

#endif
