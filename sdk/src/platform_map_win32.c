/* SPDX-License-Identifier: Apache-2.0 */
/* platform_map.h over Win32: CreateFileW (the path is UTF-8), a read-only
 * file mapping and view, and ReadFile. */
#include "platform_map.h"

#include <stdio.h>
#include <stdlib.h>

#define WIN32_LEAN_AND_MEAN
#include <windows.h>

/* GetLastError's text, without the trailing line break. */
static void last_error(char *why, size_t why_size, const char *prefix)
{
    DWORD err = GetLastError();
    char text[256];
    DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL, err,
                             0, text, sizeof text, NULL);
    while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r' || text[n - 1] == '.'))
        n--;
    if (n == 0)
        snprintf(text, sizeof text, "Windows error %lu", (unsigned long)err);
    else
        text[n] = '\0';
    snprintf(why, why_size, "%s%s", prefix, text);
}

int pose__file_open(pose__file *f, const char *path, uint64_t *size, char *why, size_t why_size)
{
    int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path, -1, NULL, 0);
    wchar_t *wpath = n > 0 ? malloc((size_t)n * sizeof *wpath) : NULL;
    if (!wpath || !MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path, -1, wpath, n)) {
        free(wpath);
        snprintf(why, why_size, "cannot open: not a valid UTF-8 path");
        return -1;
    }
    HANDLE h = CreateFileW(wpath, GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_DELETE, NULL,
                           OPEN_EXISTING, FILE_ATTRIBUTE_NORMAL, NULL);
    free(wpath);
    if (h == INVALID_HANDLE_VALUE) {
        last_error(why, why_size, "cannot open: ");
        return -1;
    }
    LARGE_INTEGER sz;
    if (GetFileType(h) != FILE_TYPE_DISK || !GetFileSizeEx(h, &sz)) {
        CloseHandle(h);
        snprintf(why, why_size, "not a regular file");
        return -1;
    }
    f->handle = (intptr_t)h;
    *size = (uint64_t)sz.QuadPart;
    return 0;
}

void *pose__file_map(pose__file *f, size_t size, char *why, size_t why_size)
{
    HANDLE m = CreateFileMappingW((HANDLE)f->handle, NULL, PAGE_READONLY, 0, 0, NULL);
    if (!m) {
        last_error(why, why_size, "");
        return NULL;
    }
    /* the view keeps the mapping object alive after its handle is closed */
    void *map = MapViewOfFile(m, FILE_MAP_READ, 0, 0, size);
    if (!map)
        last_error(why, why_size, "");
    CloseHandle(m);
    return map;
}

size_t pose__file_read(pose__file *f, void *buf, size_t size, char *why, size_t why_size)
{
    size_t got = 0;
    while (got < size) {
        DWORD want = size - got > 0x40000000u ? 0x40000000u : (DWORD)(size - got), r = 0;
        if (!ReadFile((HANDLE)f->handle, (char *)buf + got, want, &r, NULL)) {
            last_error(why, why_size, "");
            break;
        }
        if (r == 0) {
            snprintf(why, why_size, "file shrank while reading");
            break;
        }
        got += r;
    }
    return got;
}

void pose__file_close(pose__file *f)
{
    CloseHandle((HANDLE)f->handle);
}

void pose__file_unmap(void *map, size_t size)
{
    (void)size; /* a view is released whole */
    UnmapViewOfFile(map);
}
