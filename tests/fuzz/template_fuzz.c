/* SPDX-License-Identifier: Apache-2.0
 * libFuzzer harness for the skeleton template reader. */
#include <stdint.h>
#include <string.h>

#include "template_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pp_template t;
    char err[512];
    if (pp_template_parse((const char *)data, size, "fuzz.json", &t, err, sizeof err) == POSE_OK) {
        /* Exercise the lookups on whatever was accepted. */
        for (size_t i = 0; i < t.joint_count; i++) {
            if (pp_template_find_joint(&t, t.joints[i].name) != (int)i)
                __builtin_trap();
            for (size_t b = 0; b < t.joints[i].bone_count; b++)
                if (pp_template_joint_of_bone(&t, t.joints[i].bones[b]) != (int)i)
                    __builtin_trap();
        }
        for (size_t i = 0; i < t.coupling_count; i++) { /* couplings name known joints, or
                                                           two different tissues */
            const pp_template_coupling *c = &t.couplings[i];
            const int soft = c->joint < 0;
            if ((soft ? !c->tissue[0] || !c->to[0] || strcmp(c->tissue, c->to) == 0 ||
                            c->reach_mm > 10.0f
                      : (size_t)c->joint >= t.joint_count || c->tissue[0] || c->to[0]) ||
                !(c->reach_mm > 0.0f && c->stiffness > 0.0f))
                __builtin_trap();
        }
    } else if (err[0] == '\0' || !strstr(err, "fuzz.json")) {
        __builtin_trap(); /* every failure names the source */
    }
    pp_template_free(&t);
    return 0;
}
