/* edmd_extra.c -- the event loops of rough particles (rule.h) and of a vibrating wall
 * (vibwall.h) with constant velocity: edmd.c once more, in a unit of its own, so that the
 * compiler's inlining and cloning of the plain loop in edmd.c stays what it was without
 * them (edmd.c says why).  It defines gr_edmd_advance_extra (engine.h). */
#define GR_EDMD_EXTRA_UNIT 1
#include "edmd.c"
