/* SPDX-License-Identifier: Apache-2.0 */
/* Section layouts of rig file version 1 and the CRC-32 that guards them. */
#include <stddef.h>

#include "rig_format.h"
#include "rt_thread.h"

const char *pose__section_name(uint32_t type)
{
    switch (type) {
    case POSE__SEC_SKELETON: return "skeleton";
    case POSE__SEC_TETMESH: return "tetmesh";
    case POSE__SEC_WEIGHTS: return "weights";
    case POSE__SEC_COR: return "cor";
    case POSE__SEC_TISSUES: return "tissues";
    case POSE__SEC_METADATA: return "metadata";
    case POSE__SEC_VOLUMES: return "volumes";
    case POSE__SEC_CLINICAL: return "clinical";
    case POSE__SEC_FEM: return "fem";
    case POSE__SEC_COUPLINGS: return "couplings";
    case POSE__SEC_SOFT_COUPLINGS: return "soft_couplings";
    default: return "unknown";
    }
}

bool pose__section_known(uint32_t type)
{
    return (type >= POSE__SEC_SKELETON && type <= POSE__SEC_METADATA) || type == POSE__SEC_CLINICAL ||
           type == POSE__SEC_FEM || type == POSE__SEC_VOLUMES || type == POSE__SEC_COUPLINGS ||
           type == POSE__SEC_SOFT_COUPLINGS;
}

pose__skeleton_layout pose__skeleton_layout_of(uint64_t joints)
{
    pose__skeleton_layout l;
    l.names = POSE__RIG_SECTION_HEADER;
    l.parents = l.names + pose__align64(joints * 64u);
    l.rest_model = l.parents + pose__align64(joints * 4u);
    l.limits = l.rest_model + pose__align64(joints * 28u);
    l.size = l.limits + pose__align64(joints * 32u);
    return l;
}

pose__tetmesh_layout pose__tetmesh_layout_of(uint64_t vertices, uint64_t tets)
{
    pose__tetmesh_layout l;
    l.positions = POSE__RIG_SECTION_HEADER;
    l.tets = l.positions + pose__align64(vertices * 12u);
    l.labels = l.tets + pose__align64(tets * 16u);
    l.size = l.labels + pose__align64(tets * 2u);
    return l;
}

pose__weights_layout pose__weights_layout_of(uint64_t vertices, uint64_t influences)
{
    pose__weights_layout l;
    l.joints = POSE__RIG_SECTION_HEADER;
    l.weights = l.joints + pose__align64(vertices * influences * 2u);
    l.size = l.weights + pose__align64(vertices * influences * 4u);
    return l;
}

uint64_t pose__cor_size_of(uint64_t vertices)
{
    return POSE__RIG_SECTION_HEADER + pose__align64(vertices * 12u);
}

uint64_t pose__metadata_size_of(uint64_t length)
{
    return POSE__RIG_SECTION_HEADER + pose__align64(length + 1u);
}

uint64_t pose__clinical_size_of(uint64_t joints)
{
    /* 192-byte records keep every record on a 64-byte boundary: no padding. */
    return POSE__RIG_SECTION_HEADER + joints * POSE__RIG_CLINICAL_RECORD;
}

uint64_t pose__couplings_size_of(uint64_t count)
{
    return POSE__RIG_SECTION_HEADER + pose__align64(count * POSE__RIG_COUPLING_RECORD);
}

uint64_t pose__soft_couplings_size_of(uint64_t count)
{
    return POSE__RIG_SECTION_HEADER + pose__align64(count * POSE__RIG_SOFT_COUPLING_RECORD);
}

uint64_t pose__tissue_data_size(uint64_t vertices, uint64_t triangles)
{
    return pose__align64(vertices * 12u) + pose__align64(triangles * 12u) +
           pose__align64(vertices * 4u) + pose__align64(vertices * 16u);
}

/* Slicing-by-8: eight bytes per step; rig files reach a few hundred MB and
 * their CRCs are checked at every load. */
static uint32_t crc_table[8][256];
static pose__once crc_once = POSE__ONCE_INIT;

static void crc_init(void)
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++)
            c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; i++)
        for (int t = 1; t < 8; t++)
            crc_table[t][i] = (crc_table[t - 1][i] >> 8) ^ crc_table[0][crc_table[t - 1][i] & 0xFFu];
}

uint32_t pose__crc32(uint32_t crc, const void *data, size_t size)
{
    pose__call_once(&crc_once, crc_init);
    const uint8_t *p = data;
    uint32_t c = ~crc;
    while (size >= 8) {
        uint32_t lo = c ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                           (uint32_t)p[3] << 24);
        uint32_t hi = (uint32_t)p[4] | (uint32_t)p[5] << 8 | (uint32_t)p[6] << 16 |
                      (uint32_t)p[7] << 24;
        c = crc_table[7][lo & 0xFFu] ^ crc_table[6][(lo >> 8) & 0xFFu] ^
            crc_table[5][(lo >> 16) & 0xFFu] ^ crc_table[4][lo >> 24] ^
            crc_table[3][hi & 0xFFu] ^ crc_table[2][(hi >> 8) & 0xFFu] ^
            crc_table[1][(hi >> 16) & 0xFFu] ^ crc_table[0][hi >> 24];
        p += 8;
        size -= 8;
    }
    while (size--)
        c = crc_table[0][(c ^ *p++) & 0xFFu] ^ (c >> 8);
    return ~c;
}
