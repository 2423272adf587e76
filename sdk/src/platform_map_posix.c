/* SPDX-License-Identifier: Apache-2.0 */
/* platform_map.h over POSIX: open, fstat, mmap and read. */
#include "platform_map.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

int pose__file_open(pose__file *f, const char *path, uint64_t *size, char *why, size_t why_size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        snprintf(why, why_size, "cannot open: %s", strerror(errno));
        return -1;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        snprintf(why, why_size, "not a regular file");
        return -1;
    }
    f->handle = fd;
    *size = (uint64_t)sb.st_size;
    return 0;
}

void *pose__file_map(pose__file *f, size_t size, char *why, size_t why_size)
{
    void *map = mmap(NULL, size, PROT_READ, MAP_PRIVATE, (int)f->handle, 0);
    if (map == MAP_FAILED) {
        snprintf(why, why_size, "%s", strerror(errno));
        return NULL;
    }
    return map;
}

size_t pose__file_read(pose__file *f, void *buf, size_t size, char *why, size_t why_size)
{
    size_t got = 0;
    while (got < size) {
        ssize_t r = read((int)f->handle, (char *)buf + got, size - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0) {
            snprintf(why, why_size, "%s", r < 0 ? strerror(errno) : "file shrank while reading");
            break;
        }
        got += (size_t)r;
    }
    return got;
}

void pose__file_close(pose__file *f)
{
    close((int)f->handle);
}

void pose__file_unmap(void *map, size_t size)
{
    munmap(map, size);
}
