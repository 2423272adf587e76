/* SPDX-License-Identifier: Apache-2.0 */
#include "ex_scene.h"

#include "ex_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

double ex_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int ex_scene_open(ex_scene *sc, const char *rig_path, char *err, size_t err_size)
{
    memset(sc, 0, sizeof *sc);
    sc->weight_joint = -1;
    if (pose_rig_load(rig_path, &sc->rig) < 0) {
        snprintf(err, err_size, "cannot load rig: %s", pose_last_error());
        return -1;
    }
    if (pose_state_create(sc->rig, &sc->state) < 0) {
        snprintf(err, err_size, "cannot create a pose state: %s", pose_last_error());
        ex_scene_close(sc);
        return -1;
    }
    sc->tissue_count = pose_rig_tissue_count(sc->rig);
    sc->tissue_visible = malloc(sc->tissue_count ? sc->tissue_count : 1);
    if (!sc->tissue_visible) {
        snprintf(err, err_size, "out of memory");
        ex_scene_close(sc);
        return -1;
    }
    memset(sc->tissue_visible, 1, sc->tissue_count);
    return ex_scene_apply(sc, err, err_size);
}

void ex_scene_close(ex_scene *sc)
{
    pose_state_free(sc->state);
    pose_rig_free(sc->rig);
    free(sc->tissue_visible);
    free(sc->boundary);
    free(sc->boundary_normals);
    free(sc->vertex_weight);
    memset(sc, 0, sizeof *sc);
}

int ex_scene_apply(ex_scene *sc, char *err, size_t err_size)
{
    double t0 = ex_now();
    if (pose_apply(sc->state) < 0) {
        snprintf(err, err_size, "pose_apply failed: %s", pose_last_error());
        return -1;
    }
    sc->last_apply_ms = 1e3 * (ex_now() - t0);
    return 0;
}

static void ex_grow(float bmin[3], float bmax[3], const float *xyz, size_t n)
{
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            float v = xyz[3 * i + (size_t)a];
            if (v < bmin[a])
                bmin[a] = v;
            if (v > bmax[a])
                bmax[a] = v;
        }
}

void ex_scene_bounds(const ex_scene *sc, int posed, float bmin[3], float bmax[3])
{
    for (int a = 0; a < 3; a++) {
        bmin[a] = INFINITY;
        bmax[a] = -INFINITY;
    }
    for (size_t t = 0; t < sc->tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(sc->rig, (int)t, &ti) < 0)
            continue;
        size_t n = ti.vertex_count;
        const float *p = posed ? pose_tissue_positions(sc->state, (int)t, &n) : ti.rest_positions;
        if (p)
            ex_grow(bmin, bmax, p, n);
    }
    /* The tet mesh is what is drawn in weight mode, and all there is without tissues. */
    if (!(bmin[0] <= bmax[0]) || sc->weight_joint >= 0) {
        pose_tet_info tet;
        if (pose_rig_tet_info(sc->rig, &tet) == POSE_OK) {
            size_t n = tet.vertex_count;
            const float *p = posed ? pose_tet_positions(sc->state, &n) : tet.rest_positions;
            if (p)
                ex_grow(bmin, bmax, p, n);
        }
    }
    if (!(bmin[0] <= bmax[0]))
        for (int a = 0; a < 3; a++) {
            bmin[a] = -1.0f;
            bmax[a] = 1.0f;
        }
}

int ex_scene_skin_translucent(const ex_scene *sc)
{
    if (sc->skin_mode == EX_SKIN_TRANSLUCENT)
        return 1;
    if (sc->skin_mode != EX_SKIN_AUTO)
        return 0;
    for (size_t t = 0; t < sc->tissue_count; t++) {
        pose_tissue_info ti;
        if (pose_rig_tissue_info(sc->rig, (int)t, &ti) == POSE_OK && ti.kind != POSE_TISSUE_SKIN)
            return 1;
    }
    return 0;
}

void ex_scene_tissue_color(pose_tissue_kind kind, float rgba[4])
{
    static const float colors[5][4] = {
        {0.92f, 0.74f, 0.64f, 0.30f}, /* skin */
        {0.93f, 0.91f, 0.82f, 1.0f},  /* bone */
        {0.72f, 0.24f, 0.22f, 1.0f},  /* muscle */
        {0.66f, 0.33f, 0.46f, 1.0f},  /* organ */
        {0.55f, 0.62f, 0.72f, 1.0f},  /* other */
    };
    int k = (int)kind >= 0 && (int)kind <= 4 ? (int)kind : 4;
    memcpy(rgba, colors[k], sizeof colors[k]);
}

/* Faces are keyed by their sorted vertex triple; a face seen twice is interior. */
typedef struct ex_face {
    uint32_t key[3];
    uint32_t v[3]; /* original orientation, outward for the owning tet */
} ex_face;

static int ex_face_cmp(const void *a, const void *b)
{
    const ex_face *fa = a, *fb = b;
    for (int i = 0; i < 3; i++)
        if (fa->key[i] != fb->key[i])
            return fa->key[i] < fb->key[i] ? -1 : 1;
    return 0;
}

static void ex_sort3(uint32_t k[3])
{
    uint32_t t;
    if (k[0] > k[1]) { t = k[0]; k[0] = k[1]; k[1] = t; }
    if (k[1] > k[2]) { t = k[1]; k[1] = k[2]; k[2] = t; }
    if (k[0] > k[1]) { t = k[0]; k[0] = k[1]; k[1] = t; }
}

static int ex_build_boundary(ex_scene *sc, const pose_tet_info *tet, char *err, size_t err_size)
{
    /* Faces opposite each vertex, wound outward for a positively oriented tet. */
    static const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    ex_face *all = malloc(sizeof *all * 4 * (tet->tet_count ? tet->tet_count : 1));
    sc->boundary_normals = calloc(3 * (tet->vertex_count ? tet->vertex_count : 1), sizeof(float));
    sc->vertex_weight = calloc(tet->vertex_count ? tet->vertex_count : 1, sizeof(float));
    if (!all || !sc->boundary_normals || !sc->vertex_weight) {
        free(all);
        snprintf(err, err_size, "out of memory building the tet mesh boundary");
        return -1;
    }
    const float *p = tet->rest_positions;
    for (size_t t = 0; t < tet->tet_count; t++) {
        const uint32_t *v = tet->tets + 4 * t;
        /* Orientation from the signed volume, so either winding convention works. */
        float a[3], b[3], c[3];
        for (int i = 0; i < 3; i++) {
            a[i] = p[3 * v[1] + (size_t)i] - p[3 * v[0] + (size_t)i];
            b[i] = p[3 * v[2] + (size_t)i] - p[3 * v[0] + (size_t)i];
            c[i] = p[3 * v[3] + (size_t)i] - p[3 * v[0] + (size_t)i];
        }
        float vol = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                    a[2] * (b[0] * c[1] - b[1] * c[0]);
        for (int f = 0; f < 4; f++) {
            ex_face *fc = &all[4 * t + (size_t)f];
            for (int i = 0; i < 3; i++)
                fc->v[i] = v[faces[f][vol >= 0.0f ? i : 2 - i]];
            memcpy(fc->key, fc->v, sizeof fc->key);
            ex_sort3(fc->key);
        }
    }
    size_t n = 4 * tet->tet_count, out = 0;
    qsort(all, n, sizeof *all, ex_face_cmp);
    sc->boundary = malloc(sizeof(uint32_t) * 3 * (n ? n : 1));
    if (!sc->boundary) {
        free(all);
        snprintf(err, err_size, "out of memory building the tet mesh boundary");
        return -1;
    }
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && ex_face_cmp(&all[i], &all[j]) == 0)
            j++;
        if (j - i == 1) {
            memcpy(sc->boundary + 3 * out, all[i].v, sizeof all[i].v);
            out++;
        }
        i = j;
    }
    sc->boundary_count = out;
    free(all);
    return 0;
}

int ex_scene_set_weight_joint(ex_scene *sc, int joint, char *err, size_t err_size)
{
    if (joint < 0) {
        sc->weight_joint = -1;
        return 0;
    }
    if ((size_t)joint >= pose_rig_joint_count(sc->rig)) {
        snprintf(err, err_size, "joint index %d out of range (the rig has %zu joints)", joint,
                 pose_rig_joint_count(sc->rig));
        return -1;
    }
    pose_tet_info tet;
    if (pose_rig_tet_info(sc->rig, &tet) < 0) {
        snprintf(err, err_size, "the rig has no tet mesh: %s", pose_last_error());
        return -1;
    }
    if (!sc->boundary && ex_build_boundary(sc, &tet, err, err_size) < 0)
        return -1;
    for (size_t v = 0; v < tet.vertex_count; v++) {
        float w = 0.0f;
        for (unsigned k = 0; k < tet.influences; k++)
            if (tet.weight_joints[tet.influences * v + k] == (uint16_t)joint)
                w += tet.weights[tet.influences * v + k];
        sc->vertex_weight[v] = w;
    }
    sc->weight_joint = joint;
    return 0;
}

void ex_scene_update_boundary_normals(ex_scene *sc)
{
    size_t nv;
    const float *p = pose_tet_positions(sc->state, &nv);
    if (!p || !sc->boundary)
        return;
    memset(sc->boundary_normals, 0, 3 * nv * sizeof(float));
    for (size_t f = 0; f < sc->boundary_count; f++) {
        const uint32_t *v = sc->boundary + 3 * f;
        float a[3], b[3], n[3];
        for (int i = 0; i < 3; i++) {
            a[i] = p[3 * v[1] + (size_t)i] - p[3 * v[0] + (size_t)i];
            b[i] = p[3 * v[2] + (size_t)i] - p[3 * v[0] + (size_t)i];
        }
        n[0] = a[1] * b[2] - a[2] * b[1];
        n[1] = a[2] * b[0] - a[0] * b[2];
        n[2] = a[0] * b[1] - a[1] * b[0];
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++)
                sc->boundary_normals[3 * v[k] + (size_t)i] += n[i];
    }
    for (size_t v = 0; v < nv; v++) {
        float *n = sc->boundary_normals + 3 * v;
        float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (l > 0.0f)
            for (int i = 0; i < 3; i++)
                n[i] /= l;
    }
}

int ex_parse_method(const char *s)
{
    if (!strcasecmp(s, "lbs"))
        return POSE_LBS;
    if (!strcasecmp(s, "dqs"))
        return POSE_DQS;
    if (!strcasecmp(s, "cor"))
        return POSE_COR;
    if (!strcasecmp(s, "fem"))
        return POSE_FEM;
    return -1;
}

const char *ex_method_name(pose_method m)
{
    switch (m) {
    case POSE_LBS: return "LBS";
    case POSE_DQS: return "DQS";
    case POSE_COR: return "CoR";
    case POSE_FEM: return "FEM";
    }
    return "?";
}

int ex_scene_set_pose_arg(ex_scene *sc, const char *arg, char *err, size_t err_size)
{
    const char *eq = strchr(arg, '=');
    char name[64];
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof name) {
        snprintf(err, err_size, "--pose '%s': expected JOINT=RX,RY,RZ (degrees)", arg);
        return -1;
    }
    memcpy(name, arg, (size_t)(eq - arg));
    name[eq - arg] = '\0';
    float deg[3];
    const char *s = eq + 1;
    for (int i = 0; i < 3; i++) {
        char *end;
        errno = 0;
        double d = strtod(s, &end);
        if (end == s || errno || !isfinite(d) || (i < 2 && *end != ',') || (i == 2 && *end != '\0')) {
            snprintf(err, err_size, "--pose '%s': expected three angles in degrees, as %s=0,45,0", arg,
                     name);
            return -1;
        }
        deg[i] = (float)d;
        s = end + 1;
    }
    int j = pose_rig_find_joint(sc->rig, name);
    if (j < 0) {
        int n = snprintf(err, err_size, "--pose: the rig has no joint '%s'; joints:", name);
        for (size_t k = 0; k < pose_rig_joint_count(sc->rig) && n > 0 && (size_t)n < err_size; k++) {
            pose_joint_info ji;
            if (pose_rig_joint_info(sc->rig, (int)k, &ji) == POSE_OK)
                n += snprintf(err + n, err_size - (size_t)n, " %s", ji.name);
        }
        return -1;
    }
    pose_status st = pose_set_joint_euler(sc->state, j, deg, POSE_EULER_XYZ);
    if (st < 0) {
        snprintf(err, err_size, "--pose '%s': %s", arg, pose_last_error());
        return -1;
    }
    if (st == POSE_CLAMPED) {
        fprintf(stderr, "note: --pose %s clamped by the joint's limits: %s\n", arg, pose_last_error());
        ex_clamp_log *log = &sc->clamped;
        if (log->count < sizeof log->text / sizeof log->text[0])
            snprintf(log->text[log->count++], sizeof log->text[0], "--pose %s: %s", arg, pose_last_error());
    }
    return 0;
}

void ex_clamp_log_json(const ex_clamp_log *log, void *file)
{
    FILE *f = file;
    fputs("\"clamped\": [", f);
    for (size_t i = 0; i < log->count; i++) {
        fputs(i ? ", " : "", f);
        ex_json_string(f, log->text[i]);
    }
    fputc(']', f);
}

void ex_weight_color(float w, float rgb[3])
{
    w = w < 0.0f ? 0.0f : w > 1.0f ? 1.0f : w;
    /* blue (0) -> cyan -> green -> yellow -> red (1), as in the paper's weight plots */
    float r = w < 0.5f ? 0.0f : w < 0.75f ? (w - 0.5f) * 4.0f : 1.0f;
    float g = w < 0.25f ? w * 4.0f : w < 0.75f ? 1.0f : (1.0f - w) * 4.0f;
    float b = w < 0.25f ? 1.0f : w < 0.5f ? (0.5f - w) * 4.0f : 0.0f;
    rgb[0] = r;
    rgb[1] = g;
    rgb[2] = b;
}
