/* schedstate.h -- a particle's scheduling state: what the event loop predicted for it.
 *
 * Everything an event reads and writes about one particle besides its position record,
 * in one cache line: at large N each separate array would be one more miss per event. */
#ifndef GR_SCHEDSTATE_H
#define GR_SCHEDSTATE_H

#include <stdint.h>

typedef struct {
    double t_coll;   /* predicted pair or wall collision, +inf if none */
    double t_cross;  /* next cell crossing (lists: leaving the shell), +inf if none */
    double t_last;   /* time of this particle's last collision (TC model, collapse) */
    int64_t count;   /* this particle's collisions, pair and wall */
    int64_t pcount;  /* partner's collision counter when predicted */
    int32_t partner; /* >= 0: particle; -1: none; <= -2: wall -(2 + 2*axis + side) */
    int32_t last;    /* partner of the last collision (a wall as in `partner`), -1 none */
    int32_t c[3];    /* cell coordinates (the first dim used; lists: of the centre) */
    int8_t cross;    /* 2*axis + (1 if moving up), -1 none */
    int8_t streak;   /* consecutive collisions each within eps_t of the previous one,
                      * saturating (only "more than GR_COLLAPSE_STREAK" matters) */
    int16_t nn;      /* length of the neighbour list (list mode) */
} gr_sched;
typedef char gr_sched_fills_one_line[sizeof(gr_sched) == 64 ? 1 : -1];

#endif
