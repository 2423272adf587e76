/* SPDX-License-Identifier: Apache-2.0
 * Scalar channels (HID axes, CAN signals) -> joint rotations.
 * Per entry, in this order: calibration (two-point or offset/scale) to
 * degrees, inversion, One Euro filter, deadband (hold the output until the
 * value moves more than the band away from it), limits. The entries of one
 * joint then compose as rotations: clinical angles ("dof") about the joint's
 * anatomical axes onto its neutral offset (pose.h, pose_joint_clinical), or
 * rest-frame Euler angles ("axis") in the joint's order. Never by adding
 * angles of different joints' frames. */
#include <stdlib.h>
#include <string.h>

#include "mapping.h"
#include "pb_math.h"

typedef struct chan_state {
    pb_map_channel m;
    size_t channel;   /* source channel index */
    int joint;        /* rig joint */
    pb_one_euro f;
    double out;       /* latest output, degrees */
    int64_t t_prev;
    int has_value;
} chan_state;

struct pb_chanmap {
    int count;
    chan_state *e;
    int joint_count;
    int *joint_entries; /* per rig joint: number of entries driving it */
    pose_euler_order *joint_order;
    const pb_rig_skel *rig; /* clinical axes and neutral offsets; outlives the chanmap */
};

void pb_chanmap_free(pb_chanmap *c)
{
    if (!c)
        return;
    free(c->e);
    free(c->joint_entries);
    free(c->joint_order);
    free(c);
}

double pb_map_channel_transform(const pb_map_channel *m, double raw)
{
    double v = raw;
    if (m->calib == PB_CALIB_TWO_POINT)
        v = m->deg[0] + (raw - m->raw[0]) * (m->deg[1] - m->deg[0]) / (m->raw[1] - m->raw[0]);
    else if (m->calib == PB_CALIB_LINEAR)
        v = (raw + m->offset) * m->scale;
    if (m->invert)
        v = -v;
    return v;
}

static double limit(const pb_map_channel *m, double v)
{
    if (m->has_limits) {
        if (v < m->limit[0])
            v = m->limit[0];
        if (v > m->limit[1])
            v = m->limit[1];
    }
    return v;
}

static long find_by_usage(const pb_channel *ch, size_t n, uint32_t usage, int index)
{
    int seen = 0;
    for (size_t i = 0; i < n; i++)
        if (ch[i].usage == usage && seen++ == index)
            return (long)i;
    return -1;
}

/* The clinical angle an entry's "dof" names: the generic names, or the
 * rig's own name for one of the joint's three angles. */
static int resolve_dof(const pb_mapping *map, int i, const pb_rig_joint *J, pb_map_channel *m, pb_error *err)
{
    static const char *const generic[3] = {"flexion", "abduction", "rotation"};
    if (!(J->clinical.flags & POSE_CLINICAL_DEFINED)) {
        pb_fail(err, POSE_ERR_NOT_FOUND,
                "%s: channels[%d].dof: the rig has no neutral posture or clinical axes for joint %s (bake it "
                "from a template with \"clinical\" joints, or map rest-frame Euler angles with \"axis\")",
                map->path, i, J->name);
        return -1;
    }
    for (int k = 0; k < 3; k++)
        if (!strcmp(m->dof, generic[k]) || !strcmp(m->dof, J->clinical_names[k])) {
            m->axis = k; /* from here on: the index of the clinical angle */
            return 0;
        }
    pb_fail(err, POSE_ERR_NOT_FOUND, "%s: channels[%d].dof: joint %s has no angle '%s' (it has %s, %s, %s)",
            map->path, i, J->name, m->dof, J->clinical_names[0], J->clinical_names[1], J->clinical_names[2]);
    return -1;
}

pose_status pb_chanmap_create(const pb_mapping *map, const pb_channel *channels, size_t channel_count,
                              const pb_rig_skel *rig, pb_chanmap **out, pb_error *err)
{
    if (!map || !rig || !out || (!channels && channel_count))
        return pb_fail(err, POSE_ERR_INVALID_ARGUMENT, "pb_chanmap_create: NULL argument");
    *out = NULL;
    if (map->channel_count == 0)
        return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: no \"channels\" entries", map->path);
    pb_chanmap *c = calloc(1, sizeof *c);
    if (!c)
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    c->count = map->channel_count;
    c->joint_count = rig->joint_count;
    c->rig = rig;
    c->e = calloc((size_t)c->count, sizeof *c->e);
    c->joint_entries = calloc((size_t)(rig->joint_count > 0 ? rig->joint_count : 1), sizeof *c->joint_entries);
    c->joint_order = calloc((size_t)(rig->joint_count > 0 ? rig->joint_count : 1), sizeof *c->joint_order);
    if (!c->e || !c->joint_entries || !c->joint_order) {
        pb_chanmap_free(c);
        return pb_fail(err, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (int i = 0; i < c->count; i++) {
            chan_state *E = &c->e[i];
        E->m = map->channels[i];
        long ch;
        if (E->m.channel[0]) {
            ch = -1;
            for (size_t k = 0; k < channel_count && ch < 0; k++)
                if (strncmp(channels[k].name, E->m.channel, sizeof channels[k].name) == 0)
                    ch = (long)k;
            if (ch < 0) {
                pb_chanmap_free(c);
                return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: channels[%d].channel: the source has no channel '%s'",
                               map->path, i, map->channels[i].channel);
            }
        } else {
            ch = find_by_usage(channels, channel_count, E->m.usage, E->m.usage_index);
            if (ch < 0) {
                pb_chanmap_free(c);
                return pb_fail(err, POSE_ERR_NOT_FOUND,
                               "%s: channels[%d].usage: the source has no channel #%d with usage 0x%08x", map->path,
                               i, map->channels[i].usage_index, (unsigned)map->channels[i].usage);
            }
        }
        E->channel = (size_t)ch;
        E->joint = pb_rig_skel_find(rig, E->m.joint);
        if (E->joint < 0) {
            pb_chanmap_free(c);
            return pb_fail(err, POSE_ERR_NOT_FOUND, "%s: channels[%d].joint: the rig has no joint '%s'", map->path, i,
                           map->channels[i].joint);
        }
        if (E->m.axis < 0 && resolve_dof(map, i, &rig->joints[E->joint], &E->m, err) < 0) {
            pb_chanmap_free(c);
            return POSE_ERR_NOT_FOUND;
        }
        /* One joint's entries are all clinical or all rest-frame Euler: the two do not compose. */
        for (int k = 0; k < i; k++)
            if (c->e[k].joint == E->joint && !c->e[k].m.dof[0] != !E->m.dof[0]) {
                pb_chanmap_free(c);
                return pb_fail(err, POSE_ERR_INVALID_DATA,
                               "%s: channels[%d]: joint %s mixes \"dof\" and \"axis\" entries", map->path, i,
                               map->channels[i].joint);
            }
        if (c->joint_entries[E->joint]++ && !E->m.dof[0] && c->joint_order[E->joint] != E->m.order) {
            pb_chanmap_free(c);
            return pb_fail(err, POSE_ERR_INVALID_DATA, "%s: channels[%d].order: joint %s already uses another order",
                           map->path, i, map->channels[i].joint);
        }
        c->joint_order[E->joint] = E->m.order;
        pb_one_euro_params p = E->m.has_filter ? E->m.filter : map->has_filter ? map->filter
                                                                              : (pb_one_euro_params){0, 0, 1};
        pb_one_euro_init(&E->f, &p);
    }
    *out = c;
    return POSE_OK;
}

void pb_chanmap_update(pb_chanmap *c, const pb_update *u)
{
    for (size_t k = 0; k < u->count; k++) {
        uint32_t ch = u->channels[k];
        for (int i = 0; i < c->count; i++) {
            chan_state *E = &c->e[i];
            if (E->channel != ch)
                continue;
            double v = pb_map_channel_transform(&E->m, u->values[k]);
            if (!isfinite(v))
                continue; /* a bad sample never reaches the rig; the last value holds */
            double te = E->has_value ? (double)(u->t_ns - E->t_prev) * 1e-9 : 0.0;
            v = pb_one_euro_step(&E->f, v, te);
            if (!E->has_value || fabs(v - E->out) > E->m.deadband)
                E->out = limit(&E->m, v);
            E->t_prev = u->t_ns;
            E->has_value = 1;
        }
    }
}

double pb_chanmap_value(const pb_chanmap *c, int entry)
{
    return entry >= 0 && entry < c->count ? c->e[entry].out : 0.0;
}

/* local = R(axes[0], flexion) R(axes[1], abduction) R(axes[2], rotation) * neutral
 * (pose.h, pose_joint_clinical; libpose's pose_clinical_to_local is the same map). */
static void clinical_to_local(const pose_joint_clinical *cl, const double deg[3], double q[4])
{
    double acc[4], r[4], t[4];
    for (int k = 0; k < 4; k++)
        acc[k] = cl->neutral[k];
    for (int a = 2; a >= 0; a--) {
        double h = deg[a] * (PB_PI / 360.0), sh = sin(h);
        r[0] = cl->axes[a][0] * sh;
        r[1] = cl->axes[a][1] * sh;
        r[2] = cl->axes[a][2] * sh;
        r[3] = cos(h);
        pb_quat_mul(r, acc, t);
        pb_quat_copy(acc, t);
    }
    pb_quat_normalize(acc);
    pb_quat_copy(q, acc);
}

void pb_chanmap_pose(const pb_chanmap *c, pb_pose *out)
{
    int n = out->joint_count < c->joint_count ? out->joint_count : c->joint_count;
    for (int j = 0; j < n; j++) {
        if (!c->joint_entries[j])
            continue;
        double deg[3] = {0, 0, 0}, q[4];
        int clinical = 0;
        for (int i = 0; i < c->count; i++)
            if (c->e[i].joint == j) {
                deg[c->e[i].m.axis] += c->e[i].out;
                clinical = c->e[i].m.dof[0] != 0;
            }
        if (clinical)
            clinical_to_local(&c->rig->joints[j].clinical, deg, q);
        else
            pb_quat_from_euler(deg, c->joint_order[j], q);
        for (int k = 0; k < 4; k++)
            out->q[j][k] = (float)q[k];
        out->active[j] = 1;
    }
}
