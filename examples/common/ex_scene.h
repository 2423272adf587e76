/* SPDX-License-Identifier: Apache-2.0
 *
 * What the viewer and the renderer share above OpenGL: a loaded rig and one
 * posed state, per-tissue colour and visibility, the tet mesh's boundary
 * faces (for colouring by a bone's weight), bounds for camera framing, and
 * the command-line spellings of methods and hand-set joints.
 */
#ifndef POSE_EX_SCENE_H
#define POSE_EX_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "pose/pose.h"

/** How the skin is drawn. */
typedef enum ex_skin_mode {
    EX_SKIN_AUTO = 0,    /* translucent when the rig has other tissues, else opaque */
    EX_SKIN_TRANSLUCENT,
    EX_SKIN_OPAQUE,
    EX_SKIN_HIDDEN,
} ex_skin_mode;

/* Requests the joint limits changed, for --json (the notes on stderr say the
 * same): "--pose JOINT=...: what the limits did"; the first 16 are kept. */
typedef struct ex_clamp_log {
    char text[16][256];
    size_t count;
} ex_clamp_log;

typedef struct ex_scene {
    pose_rig *rig;
    pose_state *state;
    size_t tissue_count;
    unsigned char *tissue_visible;  /* per tissue, 0 or 1 */
    ex_skin_mode skin_mode;
    int weight_joint;               /* >= 0: draw the tet boundary coloured by this joint's weight */
    /* Tet mesh boundary (faces used by one tet only), built on first use. */
    size_t boundary_count;
    uint32_t *boundary;             /* 3 * boundary_count tet vertex indices, outward */
    float *boundary_normals;        /* 3 * tet vertex count, recomputed each frame */
    float *vertex_weight;           /* per tet vertex: weight of weight_joint */
    double last_apply_ms;           /* duration of the last ex_scene_apply */
    ex_clamp_log clamped;           /* what the joint limits changed in the --pose requests */
} ex_scene;

/** Load a rig and create a state. Returns 0, or -1 with a message in err. */
int ex_scene_open(ex_scene *sc, const char *rig_path, char *err, size_t err_size);
void ex_scene_close(ex_scene *sc);

/** pose_apply, timed into last_apply_ms. Returns 0 or -1 with a message. */
int ex_scene_apply(ex_scene *sc, char *err, size_t err_size);

/**
 * Bounds of the tissues (the tet mesh when there are none, or in weight
 * mode): of the rest pose, or with `posed` of the current pose.
 */
void ex_scene_bounds(const ex_scene *sc, int posed, float bmin[3], float bmax[3]);

/** True when skin is to be drawn translucent (resolves EX_SKIN_AUTO). */
int ex_scene_skin_translucent(const ex_scene *sc);

/** Colour (RGBA in [0,1]) of a tissue kind. */
void ex_scene_tissue_color(pose_tissue_kind kind, float rgba[4]);

/**
 * Prepare colouring by joint `joint`'s weight (-1 turns it off): builds the
 * boundary on first use. Returns 0, or -1 with a message.
 */
int ex_scene_set_weight_joint(ex_scene *sc, int joint, char *err, size_t err_size);

/** Recompute boundary vertex normals from the current tet positions. */
void ex_scene_update_boundary_normals(ex_scene *sc);

/** "lbs" / "dqs" / "cor" (any case) -> method; -1 when unknown. */
int ex_parse_method(const char *s);
const char *ex_method_name(pose_method m);

/**
 * Apply "joint=rx,ry,rz" (degrees, XYZ order) to the state. Returns 0 (also
 * when the joint limits clamped it: a note goes to stderr and into
 * sc->clamped) or -1 with a message in err.
 */
int ex_scene_set_pose_arg(ex_scene *sc, const char *arg, char *err, size_t err_size);

/** Write `"clamped": [...]` (key included): each clamped request and what the limits did. */
void ex_clamp_log_json(const ex_clamp_log *log, void *file);

/** Blue-to-red ramp for a weight in [0,1]. */
void ex_weight_color(float w, float rgb[3]);

/** Monotonic clock in seconds. */
double ex_now(void);

#endif
