/* SPDX-License-Identifier: Apache-2.0
 *
 * Command-line values shared by the example tools: frame lists, sizes,
 * bounded numbers. Each returns 0, or -1 with a message naming the option.
 */
#ifndef POSE_EX_ARGS_H
#define POSE_EX_ARGS_H

#include <stddef.h>

/** "0,30,60" or "0-90:10" (first-last:step) into a new array of frame numbers. */
int ex_parse_frames(const char *opt, const char *s, long **frames, size_t *count, char *err, size_t err_size);

/** Seconds, "0,2.5,5" or "0-10:0.5" (first-last:step, step 1 by default), into a new array. */
int ex_parse_times(const char *opt, const char *s, double **times, size_t *count, char *err, size_t err_size);

/** "800x600" with each side in [16, 8192]. */
int ex_parse_size(const char *opt, const char *s, int *w, int *h, char *err, size_t err_size);

/** A long in [lo, hi]. */
int ex_parse_long(const char *opt, const char *s, long lo, long hi, long *out, char *err, size_t err_size);

/** A finite double in [lo, hi]. */
int ex_parse_double(const char *opt, const char *s, double lo, double hi, double *out, char *err,
                    size_t err_size);

/** Write s as a JSON string literal (quotes and escapes) to f. */
void ex_json_string(void *file, const char *s);

#endif
