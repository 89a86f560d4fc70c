/* edmd_rough_vib.c -- the event loops of rough particles (rule.h) beside a vibrating wall
 * (vibwall.h), with constant velocity: edmd.c once more, in a unit of its own, so that
 * neither the plain loop in edmd.c nor the rough and vibrating-wall loops in edmd_extra.c
 * change what the compiler inlines and clones for them (edmd.c says why).  It defines
 * gr_edmd_advance_vib_rough (engine.h). */
#define GR_EDMD_VIB_ROUGH_UNIT 1
#include "edmd.c"
