/* edmd_gravity_rough.c -- the event loops of rough particles (rule.h) under gravity
 * (flight.h, GR_FLIGHT_GRAVITY), with or without a vibrating floor: edmd.c once more, in a
 * unit of its own, so that gravity's loops in edmd_gravity.c keep what the compiler
 * inlines and clones for them (edmd.c says why).  It defines gr_edmd_advance_gravity_rough
 * (engine.h). */
#define GR_EDMD_GRAVITY_ROUGH_UNIT 1
#include "edmd.c"
