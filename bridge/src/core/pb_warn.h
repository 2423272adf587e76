/* SPDX-License-Identifier: Apache-2.0
 * Warnings from parsers: input that real tools accept with a warning (a HID
 * descriptor's trailing zero byte, a DBC's repeated pseudo-message signals)
 * is accepted here too, and the warning, naming the file and the line or
 * offset, goes to the sink the calling thread installed. Parsers need no
 * extra argument: the sink is per thread, installed around a load by the
 * caller that wants the warnings (the public API keeps them per bridge, the
 * tools print them on stderr). Without a sink, warnings are dropped.
 *
 * A sink has one writer at a time (the thread it is installed on) and any
 * number of readers: a warning's text is written before count is raised, so
 * a reader on another thread (the host asking pose_bridge_warning while the
 * bridge thread reports a recording's time jump) sees whole entries only. */
#ifndef POSE_BRIDGE_WARN_H
#define POSE_BRIDGE_WARN_H

#include <stddef.h>

#define PB_WARN_MAX 32     /**< warnings kept per sink; later ones are counted only */
#define PB_WARN_LEN 256

typedef struct pb_warnings {
    char text[PB_WARN_MAX][PB_WARN_LEN];
    _Atomic size_t count;   /**< kept in text */
    _Atomic size_t dropped; /**< beyond PB_WARN_MAX */
    int echo;       /**< also print each one on stderr ("warning: ...") */
} pb_warnings;

/** Install `w` as this thread's sink (NULL removes it); returns the previous sink. */
pb_warnings *pb_warnings_install(pb_warnings *w);
/** This thread's sink, or NULL. */
pb_warnings *pb_warnings_current(void);
/** Append a warning to this thread's sink, if any. */
void pb_warn(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

#endif /* POSE_BRIDGE_WARN_H */
