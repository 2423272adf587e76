/* SPDX-License-Identifier: Apache-2.0 */
/* Writes the rig_load fuzz seeds: small valid rig files and damaged copies.
 * usage: rigfile_make_seeds OUTPUT_DIR */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pose/pose.h"
#include "rig_bytes.h"
#include "tiny_rig.h"

static int save(const char *dir, const char *name, const uint8_t *data, size_t size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0) {
        fprintf(stderr, "rigfile_make_seeds: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: rigfile_make_seeds OUTPUT_DIR\n");
        return 2;
    }
    const char *dir = argv[1];
    int bad = 0;
    static const struct { const char *name; int cor, meta, clinical, couplings, soft; } valid[] = {
        {"valid_tiny_full.rig", 1, 1, 0, 0, 0}, {"valid_tiny_no_cor.rig", 0, 1, 0, 0, 0},
        {"valid_tiny_minimal.rig", 0, 0, 0, 0, 0}, {"valid_tiny_clinical.rig", 1, 1, 1, 0, 0},
        {"valid_tiny_couplings.rig", 1, 1, 0, 1, 0}, {"valid_tiny_soft_couplings.rig", 1, 1, 0, 0, 1},
    };
    uint8_t *img;
    size_t size = 0;
    for (size_t i = 0; i < sizeof valid / sizeof valid[0]; i++) {
        tiny_rig t;
        tiny_rig_init(&t, valid[i].cor, valid[i].meta);
        if (valid[i].clinical)
            tiny_rig_add_clinical(&t);
        if (valid[i].couplings)
            tiny_rig_add_couplings(&t);
        if (valid[i].soft)
            tiny_rig_add_soft_couplings(&t);
        void *data;
        if (pose_rig_write_memory(&t.desc, NULL, &data, &size) != POSE_OK) {
            fprintf(stderr, "rigfile_make_seeds: %s\n", pose_last_error());
            return 1;
        }
        bad |= save(dir, valid[i].name, data, size);
        free(data);
    }
    tiny_rig t;
    tiny_rig_init(&t, 1, 1);
    void *data;
    if (pose_rig_write_memory(&t.desc, NULL, &data, &size) != POSE_OK)
        return 1;
    img = data; /* the damaged seeds start from the full rig */
    uint8_t *d = malloc(size);
    if (!d)
        return 1;

    memcpy(d, img, size);
    bad |= save(dir, "bad_truncated_in_weights.rig", d, (size_t)rb_offset(d, SEC_WEIGHTS) + 40);

    memcpy(d, img, size);
    d[(size_t)rb_offset(d, SEC_TETMESH) + 100] ^= 0x40;
    bad |= save(dir, "bad_crc_tetmesh.rig", d, size);

    memcpy(d, img, size);
    rb_put_u32(d + 8, 2);
    rb_fix_crcs(d, size);
    bad |= save(dir, "bad_future_version.rig", d, size);

    memcpy(d, img, size);
    {
        float nan = NAN;
        memcpy(d + rb_offset(d, SEC_WEIGHTS) + 64 + 128 + 4, &nan, 4);
        rb_fix_crcs(d, size);
    }
    bad |= save(dir, "bad_nan_weight.rig", d, size);

    memcpy(d, img, size);
    rb_put_u32(d + rb_offset(d, SEC_SKELETON) + 64 + 3 * 64 + 4, 2); /* elbow's parent = wrist */
    rb_fix_crcs(d, size);
    bad |= save(dir, "bad_parent_after_child.rig", d, size);

    memcpy(d, img, size);
    rb_put_u32(d + rb_offset(d, SEC_TETMESH) + 64 + 192 + 8, 77); /* a tet vertex index */
    rb_fix_crcs(d, size);
    bad |= save(dir, "bad_tet_index.rig", d, size);

    free(d);
    free(img);

    /* a coupling's node past the tet mesh (fem and couplings sections) */
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_couplings(&t);
    if (pose_rig_write_memory(&t.desc, NULL, &data, &size) != POSE_OK)
        return 1;
    img = data;
    rb_put_u32(img + rb_offset(img, SEC_COUPLINGS) + 64 + 32, 12);
    rb_fix_crcs(img, size);
    bad |= save(dir, "bad_coupling_node.rig", img, size);
    free(img);

    /* a soft coupling's weights summing to 0.75 (fem and soft_couplings) */
    tiny_rig_init(&t, 1, 1);
    tiny_rig_add_soft_couplings(&t);
    if (pose_rig_write_memory(&t.desc, NULL, &data, &size) != POSE_OK)
        return 1;
    img = data;
    const float quarter = 0.25f; /* weight 2 of record 1: 0.5 -> 0.25 */
    memcpy(img + rb_offset(img, SEC_SOFT_COUPLINGS) + 64 + 40 + 28, &quarter, 4);
    rb_fix_crcs(img, size);
    bad |= save(dir, "bad_soft_coupling_weights.rig", img, size);
    free(img);
    return bad;
}
