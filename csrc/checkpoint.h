/* checkpoint.h -- an engine's whole state as a flat buffer of bytes, and back.
 *
 * What an engine does next depends on more than positions and velocities: each
 * particle's prediction was computed at its own time (recomputing it later rounds
 * differently), ties between equal event times are broken by the order of the calendar
 * queue's heap and lists, and pair searches visit cells and neighbour lists in the
 * order of their linked lists.  So a checkpoint holds all of it -- particle records at
 * their own clocks, masses, image counters, scheduling states, the renumbering, the
 * queue as it stands, the cell lists, the neighbour lists, the big particles, the time
 * and every counter -- and a restored engine continues bit for bit as the saved one
 * would have.  What follows from the scene and the knobs alone (cell sizes, neighbour
 * tables, image shifts) is not stored: it is rebuilt by building an engine from the
 * same scene first, and the checkpoint is then restored into it.
 *
 * A buffer comes from a file, so nothing read from it is trusted: every size is
 * checked against the bytes there are and against the engine it is restored into,
 * every index against its range, every linked list for cycles and back links, and the
 * queue against its invariants (calendar.h) before anything of the engine changes.
 *
 * Binary layout (native byte order; a buffer from a machine of the other order, or
 * from a build whose structs differ, is refused by the header): a header (magic,
 * GR_CHECKPOINT_VERSION, byte-order mark, gr_checkpoint_layout(), sizes), the config
 * with its restitution laws (tables in full, compared on restore with the engine's), the
 * counters, then the arrays. */
#ifndef GR_CHECKPOINT_H
#define GR_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "common.h"
#include "edmd.h"

/* Bump when the order or meaning of what a checkpoint holds changes. */
#define GR_CHECKPOINT_VERSION 2 /* 2: the restitution laws */

/* A fingerprint of this build's state layout: GR_CHECKPOINT_VERSION and the sizes and
 * field offsets of the structs a checkpoint copies.  A struct that changes changes it,
 * so a file from another layout is refused even if nobody bumped the version. */
uint64_t gr_checkpoint_layout(void);

/* Bytes gr_edmd_save writes for this engine. */
size_t gr_edmd_save_size(const gr_edmd *s);

/* Write the engine's state into buf (size >= gr_edmd_save_size(s) bytes).  Does not
 * change the engine.  Returns GR_OK, or GR_ERR_VALUE if buf is too small. */
int gr_edmd_save(const gr_edmd *s, unsigned char *buf, size_t size);

/* Replace the state of s by the one in buf (size bytes).  s must be an engine built
 * from the same scene (the one the saved engine was built from) and the same knobs:
 * the header's sizes and the config must match it, and so must each particle's radius,
 * mass and bigness.  On any failure s is left as it was.  Returns GR_OK, GR_ERR_VALUE
 * (err->what names the first thing found wrong) or GR_ERR_NOMEM. */
int gr_edmd_restore(gr_edmd *s, const unsigned char *buf, size_t size, gr_error *err);

#endif
