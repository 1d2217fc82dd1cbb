/* Virtual point lights: the first-bounce hit of every pixel's path, the guiding trainer's
 * input (paper, section 3.1: the texture Pi). Layout, per pixel:
 *   position : xyz = hit point y (or the unit direction for an escaped ray), w = the density
 *              that generated y, in area measure at y (solid angle for an escaped ray), so
 *              that a neighbouring pixel x can convert it to its own solid angle;
 *   normal   : xyz = geometric normal at y (facing x0), w unused;
 *   radiance : rgb = radiance leaving y towards x0, w = the info bits as a float:
 *              PG_VPL_* bits and the strategy in bits 8..15. */
#ifndef RTPG_SHARED_VPL_H
#define RTPG_SHARED_VPL_H

#include "shared/compat.h"

PG_NAMESPACE_BEGIN

#define PG_VPL_VALID 1u
#define PG_VPL_DISTANT 2u /* escaped ray: position holds a direction */
#define PG_VPL_STRATEGY_SHIFT 8u

PG_FN uint pg_vpl_strategy(uint info) {
  return (info >> PG_VPL_STRATEGY_SHIFT) & 0xffu;
}

PG_NAMESPACE_END

#endif
