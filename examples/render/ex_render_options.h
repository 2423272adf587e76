/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-render's command line: what to render, how to look at it, where to
 * write it; and the layout bands its captions take.
 */
#ifndef POSE_EX_RENDER_OPTIONS_H
#define POSE_EX_RENDER_OPTIONS_H

#include <stdio.h>

#include "ex_scene.h"

enum { EX_RENDER_MAX_POSES = 64 };

typedef struct ex_render_options {
    const char *rig, *output, *source, *map, *caption, *weights, *focus;
    const char *poses[EX_RENDER_MAX_POSES];
    int pose_count;
    int width, height, supersample, turntable, compare, json, threads, list_joints;
    int fit_rest; /* frame the camera on the rest pose only (comparable images across calls) */
    int follow;   /* --frames: the camera follows the model (moving target, fixed distance) */
    int slices;   /* the rig's scan posed alike, as three slices beside the model */
    int method; /* -1: CoR when the rig has it, else LBS */
    long *frames;
    size_t frame_count;
    double *times; /* --times: seconds of recorded time, instead of frames */
    size_t time_count;
    double azimuth, elevation, zoom;
    int have_azimuth, have_elevation;
    unsigned hide; /* bit per pose_tissue_kind */
    ex_skin_mode skin;
} ex_render_options;

/** The --help text; ex_render_usage also says whether sources are available. */
void ex_render_usage(FILE *f);

/**
 * Parse argv into o (o->frames and o->times are allocated: free them). Returns 0, 1 when
 * --help was printed, or -1 with a message in err.
 */
int ex_render_parse(int argc, char **argv, ex_render_options *o, char *err, size_t err_size);

/** Scale of the caption font for an image this wide, and of the method labels under panels. */
int ex_render_caption_scale(int image_width);
int ex_render_label_scale(int panel_width);
/** Heights of the bands kept free of the model for the caption (top) and the labels (bottom). */
int ex_render_caption_band(const ex_render_options *o);
int ex_render_label_band(const ex_render_options *o);

#endif
