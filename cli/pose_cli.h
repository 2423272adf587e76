/* SPDX-License-Identifier: Apache-2.0
 *
 * The option parser every pose tool shares (pose-bake, pose-synth,
 * pose-render, pose-view, pose-export, each pose-bridge subcommand): GNU
 * getopt_long underneath, so options and arguments mix in any order, `--x=V`
 * and `--x V` both work and `--` ends the options; on top of it one wording
 * for every mistake, printed on stderr as "TOOL: ... (see TOOL --help)":
 *
 *   unknown option '--nope'          an option this tool does not have
 *   --map needs a value              a valued option at the end of the line,
 *                                    or followed by another of the tool's options
 *   --json takes no value            --json=1
 *   unknown option '--fr' (did you mean --frames?)   no abbreviations
 *
 *     static const struct option opts[] = {
 *         {"rig", required_argument, NULL, 'r'}, {"json", no_argument, NULL, 'j'},
 *         {"help", no_argument, NULL, 'h'}, {0}};
 *     pose_cli cli;
 *     pose_cli_begin(&cli, "pose-bridge pose", argc, argv, opts);
 *     for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;)
 *         switch (c) {
 *         case 'r': rig = cli.value; break;
 *         case POSE_CLI_ARGUMENT: source = cli.value; break;   // in command-line order
 *         case POSE_CLI_ERROR: return 2;                       // already reported
 *         ...
 *         }
 *
 * An option's `val` is what pose_cli_next returns: a character for options
 * that also have a one-letter form (it becomes -c), else any value from
 * POSE_CLI_LONG_ONLY up.
 */
#ifndef POSE_CLI_H
#define POSE_CLI_H

#include <getopt.h>

enum {
    POSE_CLI_END = -1,      /**< no more options or arguments */
    POSE_CLI_ERROR = -2,    /**< a mistake, already reported on stderr */
    POSE_CLI_ARGUMENT = 1,  /**< a positional argument (in cli.value), in command-line order */
    POSE_CLI_LONG_ONLY = 256, /**< first `val` for options without a one-letter form */
};

typedef struct pose_cli {
    const char *tool;              /**< "pose-bake", "pose-bridge replay": the messages' prefix */
    int argc;
    char **argv;
    const struct option *options;  /**< terminated by an all-zero entry */
    char shorts[128];              /**< the getopt_long optstring built from `options` */
    int after_dashes;              /**< past "--": the rest are arguments */
    const char *value;             /**< the option's value or the argument; NULL for a flag */
    char name[64];                 /**< the option as named in messages: "--map" or "-o" */
} pose_cli;

/** Start parsing argv[1..argc-1] (argv[0] is the program or subcommand name). */
void pose_cli_begin(pose_cli *cli, const char *tool, int argc, char **argv, const struct option *options);

/** The next option's val, POSE_CLI_ARGUMENT, POSE_CLI_END or POSE_CLI_ERROR. */
int pose_cli_next(pose_cli *cli);

/**
 * Report a mistake about the current option or argument as the parser does
 * ("TOOL: MESSAGE (see TOOL --help)"); returns POSE_CLI_ERROR. printf-style.
 */
int pose_cli_error(const pose_cli *cli, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** The current option's value as a long in [lo, hi]; else reported, -1. */
int pose_cli_long(const pose_cli *cli, long lo, long hi, long *out);
/** The current option's value as a finite double in [lo, hi]; else reported, -1. */
int pose_cli_double(const pose_cli *cli, double lo, double hi, double *out);

#endif /* POSE_CLI_H */
