/* scene_params.h -- the scene's numbers the engine takes from Python, listed once.
 *
 * Each is a double field of gr_edmd_config (edmd.h) of the same name, and a keyword of
 * _core.EDMD / _core.edmd_check of that name (granular/_scene_params.py declares the
 * Python side: its checks, default and unit).  The binding builds its keyword list,
 * format and destinations from this list (csrc/_core.c, edmd_from_args), a checkpoint
 * saves and compares them in this order (csrc/checkpoint.c), so a new scalar scene
 * parameter is one line here, its field in gr_edmd_config, its check in validate.c and
 * the physics that uses it.  (The box, the boundary and the restitution laws are not
 * plain numbers: the binding takes them itself.)
 *
 * Use: #define X(field) ...  then GR_SCENE_DOUBLES(X). */
#ifndef GR_SCENE_PARAMS_H
#define GR_SCENE_PARAMS_H

#define GR_SCENE_DOUBLES(X) \
    X(wall_restitution)     \
    X(restitution)          \
    X(contact_duration)     \
    X(shear_rate)           \
    X(shear_offset)         \
    X(drive_kind)           \
    X(drive_rate)           \
    X(drive_strength)       \
    X(drive_seed)           \
    X(tangential_restitution) \
    X(inertia_factor)       \
    X(friction)

#endif
