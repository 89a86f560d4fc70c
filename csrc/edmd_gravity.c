/* edmd_gravity.c -- the event loop compiled for gravity (flight.h, GR_FLIGHT_GRAVITY):
 * edmd.c once more, in a unit of its own, so that the compiler's inlining and cloning of
 * the constant-velocity loops in edmd.c stays what it was without gravity (edmd.c says
 * why).  It defines gr_edmd_advance_gravity and gr_predict_all_gravity (engine.h). */
#define GR_EDMD_GRAVITY_UNIT 1
#include "edmd.c"
