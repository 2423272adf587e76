/* SPDX-License-Identifier: Apache-2.0 */
#include "cli_maps.h"

#include <dirent.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int is_dir(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
}

int pb_cli_maps_dir(char *dir, size_t size)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            snprintf(dir, size, "%s/../share/pose/maps", exe);
            if (is_dir(dir))
                return 0;
        }
    }
    static const char *const known[] = {POSE_MAPS_INSTALL_DIR, POSE_MAPS_SOURCE_DIR};
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
        if (is_dir(known[i])) {
            snprintf(dir, size, "%s", known[i]);
            return 0;
        }
    return -1;
}

/* The file-name prefix of the mappings written for this kind of source. */
static const char *map_prefix(const char *source)
{
    size_t n = strlen(source);
    if (n > 4 && (strcmp(source + n - 4, ".bvh") == 0 || strcmp(source + n - 4, ".amc") == 0))
        return NULL; /* clips map joints by name without a mapping */
    if (strncmp(source, "hid:", 4) == 0 || strncmp(source, "hid-recording:", 14) == 0 ||
        strncmp(source, "/dev/hidraw", 11) == 0 || strncmp(source, "hidusb:", 7) == 0 ||
        (n > 4 && strcmp(source + n - 4, ".hid") == 0))
        return "hid_";
    if (strncmp(source, "usb:", 4) == 0 || strncmp(source, "usbmon:", 7) == 0 ||
        (n > 7 && strcmp(source + n - 7, ".usbmon") == 0))
        return "usb_";
    if (strncmp(source, "can", 3) == 0 || strncmp(source, "vcan", 4) == 0 || strncmp(source, "candump:", 8) == 0 ||
        (n > 4 && strcmp(source + n - 4, ".log") == 0))
        return "can_";
    return NULL;
}

void pb_cli_hint_maps(const char *source)
{
    const char *prefix = map_prefix(source);
    if (!prefix)
        return;
    char dir[PATH_MAX];
    if (pb_cli_maps_dir(dir, sizeof dir) < 0) {
        fprintf(stderr, "hint: HID, CAN and USB sources need --map MAP.json (pose's mappings are installed in "
                        "share/pose/maps)\n");
        return;
    }
    fprintf(stderr, "hint: HID, CAN and USB sources need --map MAP.json; pose's mappings are in %s:", dir);
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));)
        if (strncmp(e->d_name, prefix, strlen(prefix)) == 0 && strstr(e->d_name, ".json"))
            fprintf(stderr, " %s", e->d_name);
    if (d)
        closedir(d);
    fputc('\n', stderr);
}
