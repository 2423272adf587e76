/* SPDX-License-Identifier: Apache-2.0
 * pose-bridge: command-line front end of the input bridge.
 *
 * Adding a subcommand: create bridge/tools/cmd_<name>.c that defines
 *     const pb_command pb_cmd_<name> = {"cli-name", "summary", run_fn};
 * (see pose_bridge_cli.h) and re-run cmake. bridge/CMakeLists.txt globs
 * tools/cmd_*.c and generates the table pb_commands[] from the file names,
 * so no central list needs editing. <name> must be a C identifier
 * (cmd_hid_describe.c -> pb_cmd_hid_describe, typed as "hid-describe").
 * Each subcommand parses its own options with the tools' shared parser
 * (cli/pose_cli.h), answers --help, prints results on stdout (JSON with
 * --json) and errors on stderr, and returns 0 on success.
 */
#include <string.h>

#include "pose_bridge_cli.h"

void pb_cli_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

void pb_cli_warnings_begin(pb_warnings *w)
{
    memset(w, 0, sizeof *w);
    w->echo = 1;
    pb_warnings_install(w);
}

void pb_cli_json_warnings(FILE *f, const pb_warnings *w)
{
    fputs("\"warnings\":[", f);
    for (size_t i = 0; w && i < w->count; i++) {
        if (i)
            fputc(',', f);
        pb_cli_json_string(f, w->text[i]);
    }
    fputc(']', f);
    if (w && w->dropped)
        fprintf(f, ",\"warnings_dropped\":%zu", w->dropped);
}

void pb_cli_json_warnings_line(FILE *f, const pb_warnings *w)
{
    if (!w || (w->count == 0 && w->dropped == 0))
        return;
    fputc('{', f);
    pb_cli_json_warnings(f, w);
    fputs("}\n", f);
}

static void usage(FILE *f)
{
    fprintf(f, "usage: pose-bridge <command> [options]   (pose-bridge <command> --help)\n\ncommands:\n");
    for (const pb_command *const *c = pb_commands; *c; c++)
        fprintf(f, "  %-16s %s\n", (*c)->name, (*c)->summary);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    for (const pb_command *const *c = pb_commands; *c; c++)
        if (strcmp((*c)->name, argv[1]) == 0)
            return (*c)->run(argc - 1, argv + 1);
    fprintf(stderr, "pose-bridge: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}
