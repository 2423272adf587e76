/* SPDX-License-Identifier: Apache-2.0
 * A whitespace tokenizer over a NUL-terminated text buffer that tracks line
 * numbers, shared by the BVH, ASF and AMC parsers. It treats \r as
 * whitespace, so Windows line endings and trailing blanks need no care. */
#ifndef POSE_BRIDGE_TEXT_H
#define POSE_BRIDGE_TEXT_H

#include <stddef.h>

typedef struct pb_text {
    const char *p, *end; /**< cursor; *end == '\0' */
    const char *name;    /**< file name for messages */
    long line;           /**< 1-based line of the cursor */
} pb_text;

typedef struct pb_token {
    const char *s;
    size_t n; /**< 0 at end of input */
    long line;
} pb_token;

void pb_text_init(pb_text *t, const char *data, size_t size, const char *name);
/** Skip blanks within the line (not newlines). */
void pb_text_skip_blanks(pb_text *t);
/** Skip all whitespace, counting newlines; `#` starts a comment when comments is set. */
void pb_text_skip_space(pb_text *t, int comments);
/** Next token across lines (n == 0 at end). */
pb_token pb_text_next(pb_text *t, int comments);
/** Next token on the current line only (n == 0 at end of line or input). */
pb_token pb_text_next_in_line(pb_text *t);
/** Move past the end of the current line. */
void pb_text_skip_line(pb_text *t);
/** Token equals the NUL-terminated word (case-sensitive). */
int pb_token_is(pb_token tk, const char *word);
/** Token equals the word ignoring ASCII case. */
int pb_token_is_nocase(pb_token tk, const char *word);
/** Parse the whole token as a finite double; 0 on success, -1 if not a number, -2 if NaN/inf. */
int pb_token_double(pb_token tk, double *out);
/** Parse the whole token as a non-negative integer <= max; 0 on success. */
int pb_token_count(pb_token tk, long max, long *out);
/** Copy the token into buf (truncated, NUL-terminated) for messages and names. */
const char *pb_token_str(pb_token tk, char *buf, size_t size);

#endif /* POSE_BRIDGE_TEXT_H */
