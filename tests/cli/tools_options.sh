#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every tool and every pose-bridge subcommand parses its options with the one
# shared parser (cli/pose_cli.h), so each says the same thing about the same
# mistake: an unknown option is "unknown option", a valued option without
# its value "needs a value" (each valued option its --help lists is tried
# last on the line), --help exits 0. A tool or subcommand with a parser of
# its own fails here.
#   tools_options.sh TOOL... (pose-bridge is expanded into its subcommands)
set -uo pipefail
fail=0
check() { # <what> <expected exit> <expected stderr text> <command...>
    local what=$1 want_rc=$2 want=$3; shift 3
    local err rc
    err=$("$@" 2>&1 >/dev/null </dev/null)
    rc=$?
    if [ "$rc" -ne "$want_rc" ] || ! grep -qF -- "$want" <<<"$err"; then
        echo "FAIL: $what: exit $rc (want $want_rc), stderr: ${err:-(empty)} (want '$want')" >&2
        fail=1
    fi
}
check_tool() { # <name for messages> <command...>
    local name=$1; shift
    local help
    help=$("$@" --help) || { echo "FAIL: $name --help exits non-zero" >&2; fail=1; return; }
    check "$name --no-such-option" 2 "unknown option '--no-such-option'" "$@" --no-such-option
    check "$name --json=1" 2 "takes no value" "$@" --help=1
    # Options shown with a value in --help ("--rig RIG", "-o FILE", "--frames N").
    local opts
    opts=$(grep -oE '(^|[ [(|,])(--[a-z][a-z0-9-]*|-[a-zA-Z]) [A-Z][A-Z0-9_.|,]*' <<<"$help" |
        sed -E 's/^[ [(|,]//; s/ .*//' | sort -u)
    for o in $opts; do
        check "$name ... $o" 2 "$o needs a value" "$@" "$o"
    done
    echo "$name: $(wc -w <<<"$opts") valued options checked"
}
for tool in "$@"; do
    case "$(basename "$tool")" in
    pose-bridge)
        check "pose-bridge no-such-command" 2 "unknown command 'no-such-command'" "$tool" no-such-command
        for sub in $("$tool" --help | awk '/^commands:/ {on = 1; next} on && NF {print $1}'); do
            check_tool "pose-bridge $sub" "$tool" "$sub"
        done ;;
    *) check_tool "$(basename "$tool")" "$tool" ;;
    esac
done
exit $fail
