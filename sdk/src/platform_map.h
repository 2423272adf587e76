/* SPDX-License-Identifier: Apache-2.0 */
/* Reading and mapping rig files: one implementation per platform, chosen by
 * CMake: platform_map_posix.c (open, fstat, mmap, read) and
 * platform_map_win32.c (CreateFileW on the UTF-8 path, CreateFileMapping,
 * MapViewOfFile, ReadFile). A failing call writes why into why[why_size]. */
#ifndef POSE_PLATFORM_MAP_H
#define POSE_PLATFORM_MAP_H

#include <stddef.h>
#include <stdint.h>

typedef struct pose__file {
    intptr_t handle; /* a file descriptor or a HANDLE */
} pose__file;

/** Open a regular file for reading: 0 and its size, or -1 ("cannot open: ...",
 *  "not a regular file"). */
int pose__file_open(pose__file *f, const char *path, uint64_t *size, char *why, size_t why_size);
/** Map the first `size` bytes read-only: the address, or NULL. */
void *pose__file_map(pose__file *f, size_t size, char *why, size_t why_size);
/** Read `size` bytes from the start: the bytes read (size, or fewer with why). */
size_t pose__file_read(pose__file *f, void *buf, size_t size, char *why, size_t why_size);
void pose__file_close(pose__file *f);
/** Release a mapping of pose__file_map (the file may be closed already). */
void pose__file_unmap(void *map, size_t size);

#endif /* POSE_PLATFORM_MAP_H */
