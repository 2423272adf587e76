/* SPDX-License-Identifier: Apache-2.0
 *
 * Binary glTF 2.0 writer. The JSON part is built with cJSON (Debian's
 * libcjson, already the bridge's and pose-bake's JSON library), so names are
 * escaped and the document is well formed by construction; the binary chunk
 * is our own arrays laid end to end. Why not a glTF library: cgltf is not
 * packaged in Debian 12; tinygltf is (libtinygltf-dev) but is C++ and would
 * bring a C++ runtime into a C tool for what is a JSON document and a byte
 * array; Assimp's glTF exporter (a pose-bake dependency) would make every
 * example link Assimp, and would need our skin converted into its scene
 * graph first. Readers check the result: the tests load it with three.js's
 * GLTFLoader.
 */
#include "ex_gltf.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

enum { GL_FLOAT = 5126, GL_UNSIGNED_INT = 5125, GL_UNSIGNED_SHORT = 5123 };
enum { GL_ARRAY_BUFFER = 34962, GL_ELEMENT_ARRAY_BUFFER = 34963 };

int ex_gltf_available(void)
{
    return 1;
}

/* ------------------------------------------------------------ the document */

typedef struct gl_doc {
    cJSON *root, *views, *accessors, *meshes, *nodes, *materials;
    unsigned char *bin;
    size_t bin_size, bin_cap;
    int oom;
} gl_doc;

static int doc_init(gl_doc *d)
{
    memset(d, 0, sizeof *d);
    d->root = cJSON_CreateObject();
    if (!d->root)
        return -1;
    cJSON *asset = cJSON_AddObjectToObject(d->root, "asset");
    char gen[64];
    snprintf(gen, sizeof gen, "pose %s", pose_version_string());
    if (!asset || !cJSON_AddStringToObject(asset, "version", "2.0") || !cJSON_AddStringToObject(asset, "generator", gen))
        return -1;
    d->views = cJSON_AddArrayToObject(d->root, "bufferViews");
    d->accessors = cJSON_AddArrayToObject(d->root, "accessors");
    d->materials = cJSON_AddArrayToObject(d->root, "materials");
    d->meshes = cJSON_AddArrayToObject(d->root, "meshes");
    d->nodes = cJSON_AddArrayToObject(d->root, "nodes");
    return d->views && d->accessors && d->materials && d->meshes && d->nodes ? 0 : -1;
}

static void doc_free(gl_doc *d)
{
    cJSON_Delete(d->root);
    free(d->bin);
}

/* Appends bytes to the binary chunk as one buffer view (4-byte aligned); returns its index. */
static int add_view(gl_doc *d, const void *data, size_t bytes, int target)
{
    size_t start = (d->bin_size + 3) & ~(size_t)3;
    if (start + bytes > d->bin_cap) {
        size_t cap = d->bin_cap ? d->bin_cap : 1 << 16;
        while (cap < start + bytes)
            cap *= 2;
        unsigned char *p = realloc(d->bin, cap);
        if (!p) {
            d->oom = 1;
            return -1;
        }
        d->bin = p;
        d->bin_cap = cap;
    }
    memset(d->bin + d->bin_size, 0, start - d->bin_size);
    memcpy(d->bin + start, data, bytes);
    d->bin_size = start + bytes;
    cJSON *v = cJSON_CreateObject();
    if (!v || !cJSON_AddItemToArray(d->views, v)) {
        cJSON_Delete(v);
        d->oom = 1;
        return -1;
    }
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)start);
    cJSON_AddNumberToObject(v, "byteLength", (double)bytes);
    if (target)
        cJSON_AddNumberToObject(v, "target", target);
    return cJSON_GetArraySize(d->views) - 1;
}

static int components(const char *type)
{
    return strcmp(type, "SCALAR") == 0 ? 1 : strcmp(type, "VEC3") == 0 ? 3 : strcmp(type, "VEC4") == 0 ? 4 : 16;
}

/* One accessor over a new view of `data`; float accessors of VEC3 or SCALAR
 * get min and max (glTF requires them for POSITION and animation inputs). */
static int add_accessor(gl_doc *d, const void *data, size_t count, int ctype, const char *type, int target)
{
    int nc = components(type);
    size_t csize = ctype == GL_UNSIGNED_SHORT ? 2 : 4;
    int view = add_view(d, data, count * (size_t)nc * csize, target);
    cJSON *a = cJSON_CreateObject();
    if (view < 0 || !a || !cJSON_AddItemToArray(d->accessors, a)) {
        cJSON_Delete(a);
        d->oom = 1;
        return -1;
    }
    cJSON_AddNumberToObject(a, "bufferView", view);
    cJSON_AddNumberToObject(a, "componentType", ctype);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", type);
    if (ctype == GL_FLOAT && (nc == 1 || nc == 3) && count > 0) {
        const float *f = data;
        float lo[3], hi[3];
        for (int k = 0; k < nc; k++)
            lo[k] = hi[k] = f[k];
        for (size_t i = 1; i < count; i++)
            for (int k = 0; k < nc; k++) {
                lo[k] = fminf(lo[k], f[(size_t)nc * i + k]);
                hi[k] = fmaxf(hi[k], f[(size_t)nc * i + k]);
            }
        double dlo[3] = {lo[0], nc > 1 ? lo[1] : 0, nc > 1 ? lo[2] : 0};
        double dhi[3] = {hi[0], nc > 1 ? hi[1] : 0, nc > 1 ? hi[2] : 0};
        cJSON_AddItemToObject(a, "min", cJSON_CreateDoubleArray(dlo, nc));
        cJSON_AddItemToObject(a, "max", cJSON_CreateDoubleArray(dhi, nc));
    }
    return cJSON_GetArraySize(d->accessors) - 1;
}

/* One material per tissue kind, in the order of pose_tissue_kind. */
static void add_materials(gl_doc *d)
{
    static const char *names[] = {"skin", "bone", "muscle", "organ", "other"};
    static const double colour[][4] = {{0.87, 0.69, 0.58, 1.0}, {0.93, 0.91, 0.84, 1.0}, {0.70, 0.22, 0.20, 1.0},
                                       {0.65, 0.35, 0.45, 1.0}, {0.6, 0.6, 0.6, 1.0}};
    for (int k = 0; k < 5; k++) {
        cJSON *m = cJSON_CreateObject();
        if (!m || !cJSON_AddItemToArray(d->materials, m)) {
            cJSON_Delete(m);
            d->oom = 1;
            return;
        }
        cJSON_AddStringToObject(m, "name", names[k]);
        cJSON *pbr = cJSON_AddObjectToObject(m, "pbrMetallicRoughness");
        if (pbr) {
            cJSON_AddItemToObject(pbr, "baseColorFactor", cJSON_CreateDoubleArray(colour[k], 4));
            cJSON_AddNumberToObject(pbr, "metallicFactor", 0.0);
            cJSON_AddNumberToObject(pbr, "roughnessFactor", 0.8);
        }
        cJSON_AddBoolToObject(m, "doubleSided", 1);
    }
}

/* A mesh of one triangle primitive; joints/weights may be NULL. Returns the mesh index. */
static int add_mesh(gl_doc *d, const char *name, pose_tissue_kind kind, const float *pos, const float *nrm,
                    size_t n, const uint32_t *tri, size_t ntri, const uint16_t *joints, const float *weights)
{
    cJSON *mesh = cJSON_CreateObject(), *prims, *prim, *attr;
    if (!mesh || !cJSON_AddItemToArray(d->meshes, mesh) || !cJSON_AddStringToObject(mesh, "name", name) ||
        !(prims = cJSON_AddArrayToObject(mesh, "primitives")) || !(prim = cJSON_CreateObject()) ||
        !cJSON_AddItemToArray(prims, prim) || !(attr = cJSON_AddObjectToObject(prim, "attributes"))) {
        d->oom = 1;
        return -1;
    }
    cJSON_AddNumberToObject(attr, "POSITION", add_accessor(d, pos, n, GL_FLOAT, "VEC3", GL_ARRAY_BUFFER));
    cJSON_AddNumberToObject(attr, "NORMAL", add_accessor(d, nrm, n, GL_FLOAT, "VEC3", GL_ARRAY_BUFFER));
    if (joints) {
        cJSON_AddNumberToObject(attr, "JOINTS_0",
                                add_accessor(d, joints, n, GL_UNSIGNED_SHORT, "VEC4", GL_ARRAY_BUFFER));
        cJSON_AddNumberToObject(attr, "WEIGHTS_0", add_accessor(d, weights, n, GL_FLOAT, "VEC4", GL_ARRAY_BUFFER));
    }
    cJSON_AddNumberToObject(prim, "indices",
                            add_accessor(d, tri, 3 * ntri, GL_UNSIGNED_INT, "SCALAR", GL_ELEMENT_ARRAY_BUFFER));
    cJSON_AddNumberToObject(prim, "material", kind >= POSE_TISSUE_SKIN && kind <= POSE_TISSUE_OTHER ? kind : 4);
    cJSON_AddNumberToObject(prim, "mode", 4); /* triangles */
    return cJSON_GetArraySize(d->meshes) - 1;
}

static cJSON *add_node(gl_doc *d, const char *name)
{
    cJSON *n = cJSON_CreateObject();
    if (!n || !cJSON_AddItemToArray(d->nodes, n)) {
        cJSON_Delete(n);
        d->oom = 1;
        return NULL;
    }
    cJSON_AddStringToObject(n, "name", name);
    return n;
}

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

/* The .glb container: 12-byte header, the JSON chunk (space-padded), the BIN chunk (zero-padded). */
static int doc_write(gl_doc *d, const char *path, char *err, size_t err_size)
{
    if (d->oom) {
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    cJSON *buffers = cJSON_AddArrayToObject(d->root, "buffers"), *b = cJSON_CreateObject();
    if (!buffers || !b || !cJSON_AddItemToArray(buffers, b)) {
        cJSON_Delete(b);
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    size_t bin_len = (d->bin_size + 3) & ~(size_t)3;
    cJSON_AddNumberToObject(b, "byteLength", (double)bin_len);
    char *json = cJSON_PrintUnformatted(d->root);
    if (!json) {
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    size_t json_len = strlen(json), json_pad = (json_len + 3) & ~(size_t)3;
    size_t total = 12 + 8 + json_pad + 8 + bin_len;
    if (total > UINT32_MAX) {
        free(json);
        snprintf(err, err_size, "%s: %zu bytes is past the 4 GiB a .glb can hold", path, total);
        return -1;
    }
    FILE *f = fopen(path, "wb");
    if (!f) {
        free(json);
        snprintf(err, err_size, "%s: cannot create: %s", path, strerror(errno));
        return -1;
    }
    unsigned char hdr[20];
    put_u32(hdr, 0x46546C67u); /* "glTF" */
    put_u32(hdr + 4, 2);
    put_u32(hdr + 8, (uint32_t)total);
    put_u32(hdr + 12, (uint32_t)json_pad);
    put_u32(hdr + 16, 0x4E4F534Au); /* "JSON" */
    fwrite(hdr, 1, 20, f);
    fwrite(json, 1, json_len, f);
    for (size_t i = json_len; i < json_pad; i++)
        fputc(' ', f);
    put_u32(hdr, (uint32_t)bin_len);
    put_u32(hdr + 4, 0x004E4942u); /* "BIN\0" */
    fwrite(hdr, 1, 8, f);
    if (d->bin_size)
        fwrite(d->bin, 1, d->bin_size, f);
    for (size_t i = d->bin_size; i < bin_len; i++)
        fputc(0, f);
    free(json);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        snprintf(err, err_size, "%s: write failed: %s", path, strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ posed tissues */

int ex_gltf_write_posed(const pose_state *st, const char *path, char *err, size_t err_size)
{
    const pose_rig *rig = pose_state_rig(st);
    gl_doc d;
    int rc = -1;
    if (doc_init(&d) < 0) {
        snprintf(err, err_size, "%s: out of memory", path);
        doc_free(&d);
        return -1;
    }
    add_materials(&d);
    cJSON *scene_nodes = cJSON_CreateArray();
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        pose_tissue_info ti;
        size_t n;
        if (pose_rig_tissue_info(rig, t, &ti) < 0)
            continue;
        int mesh = add_mesh(&d, ti.name, ti.kind, pose_tissue_positions(st, t, &n), pose_tissue_normals(st, t, &n),
                            ti.vertex_count, ti.triangles, ti.triangle_count, NULL, NULL);
        cJSON *node = add_node(&d, ti.name);
        if (node)
            cJSON_AddNumberToObject(node, "mesh", mesh);
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(cJSON_GetArraySize(d.nodes) - 1));
    }
    cJSON *scenes = cJSON_AddArrayToObject(d.root, "scenes"), *scene = cJSON_CreateObject();
    if (scenes && scene && cJSON_AddItemToArray(scenes, scene)) {
        cJSON_AddItemToObject(scene, "nodes", scene_nodes);
        cJSON_AddNumberToObject(d.root, "scene", 0);
        rc = doc_write(&d, path, err, err_size);
    } else {
        cJSON_Delete(scene);
        cJSON_Delete(scene_nodes);
        snprintf(err, err_size, "%s: out of memory", path);
    }
    doc_free(&d);
    return rc;
}

/* ------------------------------------------------------------ sessions */

struct ex_gltf_session {
    const pose_rig *rig;
    size_t joints, frames, cap;
    float *times;       /* frames */
    float *rotation;    /* frames * joints * 4: glTF local rotation (parent-relative) */
    float *translation; /* frames * joints * 3: glTF local translation (used for roots) */
};

static int session_tissue(const pose_tissue_info *ti)
{
    return ti->kind == POSE_TISSUE_SKIN || ti->kind == POSE_TISSUE_BONE;
}

size_t ex_gltf_session_mesh_count(const ex_gltf_session *s)
{
    size_t count = 0;
    for (int t = 0; t < (int)pose_rig_tissue_count(s->rig); t++) {
        pose_tissue_info ti;
        count += pose_rig_tissue_info(s->rig, t, &ti) == POSE_OK && session_tissue(&ti);
    }
    return count;
}

int ex_gltf_session_begin(const pose_rig *rig, ex_gltf_session **out, char *err, size_t err_size)
{
    *out = calloc(1, sizeof **out);
    if (!*out) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    (*out)->rig = rig;
    (*out)->joints = pose_rig_joint_count(rig);
    return 0;
}

void ex_gltf_session_free(ex_gltf_session *s)
{
    if (!s)
        return;
    free(s->times);
    free(s->rotation);
    free(s->translation);
    free(s);
}

static void quat_mul(float out[4], const float a[4], const float b[4])
{
    float r[4] = {a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
                  a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
                  a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
                  a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2]};
    memcpy(out, r, sizeof r);
}

static void quat_rotate(float out[3], const float q[4], const float v[3])
{
    float p[4] = {v[0], v[1], v[2], 0.0f}, c[4] = {-q[0], -q[1], -q[2], q[3]}, t[4];
    quat_mul(t, q, p);
    quat_mul(t, t, c);
    memcpy(out, t, 3 * sizeof(float));
}

static void quat_normalize(float q[4])
{
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++)
        q[k] = n > 0.0f ? q[k] / n : (k == 3 ? 1.0f : 0.0f);
}

int ex_gltf_session_add(ex_gltf_session *s, const pose_state *st, double t_s, char *err, size_t err_size)
{
    if (s->frames > 0 && t_s <= s->times[s->frames - 1]) {
        snprintf(err, err_size, "glTF animation: time %.4f s does not follow %.4f s", t_s,
                 (double)s->times[s->frames - 1]);
        return -1;
    }
    if (s->frames == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 64;
        float *t = realloc(s->times, cap * sizeof *t);
        if (t)
            s->times = t;
        float *r = t ? realloc(s->rotation, cap * s->joints * 4 * sizeof *r) : NULL;
        if (r)
            s->rotation = r;
        float *p = r ? realloc(s->translation, cap * s->joints * 3 * sizeof *p) : NULL;
        if (!p) {
            snprintf(err, err_size, "out of memory");
            return -1;
        }
        s->translation = p;
        s->cap = cap;
    }
    float *rot = s->rotation + s->frames * s->joints * 4, *tr = s->translation + s->frames * s->joints * 3;
    for (size_t j = 0; j < s->joints; j++) {
        pose_joint_info ji;
        pose_transform w, pw;
        if (pose_rig_joint_info(s->rig, (int)j, &ji) < 0 || pose_joint_world(st, (int)j, &w) < 0) {
            snprintf(err, err_size, "joint %zu: %s", j, pose_last_error());
            return -1;
        }
        if (ji.parent < 0) { /* a root: its model-space frame, the root transform included */
            memcpy(rot + 4 * j, w.rotation, 4 * sizeof(float));
            memcpy(tr + 3 * j, w.translation, 3 * sizeof(float));
        } else { /* relative to the parent: inverse(parent) * world */
            pose_joint_world(st, ji.parent, &pw);
            float inv[4] = {-pw.rotation[0], -pw.rotation[1], -pw.rotation[2], pw.rotation[3]};
            float d[3] = {w.translation[0] - pw.translation[0], w.translation[1] - pw.translation[1],
                          w.translation[2] - pw.translation[2]};
            quat_mul(rot + 4 * j, inv, w.rotation);
            quat_rotate(tr + 3 * j, inv, d);
        }
        quat_normalize(rot + 4 * j);
        /* the shorter way from the previous sample, so interpolation does not spin */
        if (s->frames > 0) {
            const float *prev = rot + 4 * j - s->joints * 4;
            if (prev[0] * rot[4 * j] + prev[1] * rot[4 * j + 1] + prev[2] * rot[4 * j + 2] +
                    prev[3] * rot[4 * j + 3] < 0.0f)
                for (int k = 0; k < 4; k++)
                    rot[4 * j + k] = -rot[4 * j + k];
        }
    }
    s->times[s->frames++] = (float)t_s;
    return 0;
}

/* Area-weighted vertex normals of the rest surface. */
static void rest_normals(const pose_tissue_info *ti, float *nrm)
{
    memset(nrm, 0, 3 * ti->vertex_count * sizeof *nrm);
    const float *p = ti->rest_positions;
    for (size_t k = 0; k < ti->triangle_count; k++) {
        const uint32_t *t = ti->triangles + 3 * k;
        float e1[3], e2[3];
        for (int c = 0; c < 3; c++) {
            e1[c] = p[3 * t[1] + c] - p[3 * t[0] + c];
            e2[c] = p[3 * t[2] + c] - p[3 * t[0] + c];
        }
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int v = 0; v < 3; v++)
            for (int c = 0; c < 3; c++)
                nrm[3 * t[v] + c] += n[c];
    }
    for (size_t v = 0; v < ti->vertex_count; v++) {
        float *n = nrm + 3 * v, len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int c = 0; c < 3; c++)
            n[c] = len > 0.0f ? n[c] / len : 0.0f;
    }
}

/* Vertex v's 4 largest weights: the embedding tet's vertex weights blended
 * by barycentric coordinates (negative ones, of vertices just outside the
 * mesh, taken as 0), renormalised. */
static void vertex_weights(const pose_tet_info *tet, uint32_t tet_index, const float bary[4], uint16_t joints[4],
                           float weights[4])
{
    uint16_t j[4 * 8];
    float w[4 * 8];
    int n = 0;
    for (int c = 0; c < 4; c++) {
        uint32_t k = tet->tets[4 * (size_t)tet_index + c];
        float b = bary[c] > 0.0f ? bary[c] : 0.0f;
        for (unsigned i = 0; i < tet->influences; i++) {
            uint16_t joint = tet->weight_joints[tet->influences * k + i];
            float wk = b * tet->weights[tet->influences * k + i];
            int m = 0;
            while (m < n && j[m] != joint)
                m++;
            if (m == n) {
                j[n] = joint;
                w[n++] = 0.0f;
            }
            w[m] += wk;
        }
    }
    float sum = 0.0f;
    for (int s = 0; s < 4; s++) {
        int best = -1;
        for (int m = 0; m < n; m++)
            if (w[m] > 0.0f && (best < 0 || w[m] > w[best]))
                best = m;
        joints[s] = best < 0 ? 0 : j[best];
        weights[s] = best < 0 ? 0.0f : w[best];
        sum += weights[s];
        if (best >= 0)
            w[best] = -1.0f;
    }
    if (sum <= 0.0f) { /* no positive weight at all: the first corner's first joint */
        joints[0] = tet->weight_joints[tet->influences * tet->tets[4 * (size_t)tet_index]];
        weights[0] = sum = 1.0f;
    }
    for (int s = 0; s < 4; s++)
        weights[s] /= sum;
}

/* One skinned mesh node per skin and bone tissue. */
static int add_skinned_meshes(gl_doc *d, const pose_rig *rig, cJSON *scene_nodes, char *err, size_t err_size)
{
    pose_tet_info tet;
    if (pose_rig_tet_info(rig, &tet) < 0) {
        snprintf(err, err_size, "the rig has no tet mesh: %s", pose_last_error());
        return -1;
    }
    for (int t = 0; t < (int)pose_rig_tissue_count(rig); t++) {
        pose_tissue_info ti;
        const uint32_t *emb;
        const float *bary;
        if (pose_rig_tissue_info(rig, t, &ti) < 0 || !session_tissue(&ti))
            continue;
        if (pose_rig_tissue_embedding(rig, t, &emb, &bary) < 0) {
            snprintf(err, err_size, "tissue %s: %s", ti.name, pose_last_error());
            return -1;
        }
        size_t n = ti.vertex_count;
        float *nrm = malloc(3 * n * sizeof *nrm + 4 * n * sizeof(float) + 4 * n * sizeof(uint16_t) + 1);
        if (!nrm) {
            snprintf(err, err_size, "out of memory");
            return -1;
        }
        float *weights = nrm + 3 * n;
        uint16_t *joints = (uint16_t *)(weights + 4 * n);
        rest_normals(&ti, nrm);
        for (size_t v = 0; v < n; v++) {
            if (ti.kind == POSE_TISSUE_BONE && ti.joint >= 0) { /* rigid on its own joint */
                joints[4 * v] = (uint16_t)ti.joint;
                weights[4 * v] = 1.0f;
                for (int k = 1; k < 4; k++) {
                    joints[4 * v + k] = 0;
                    weights[4 * v + k] = 0.0f;
                }
            } else {
                vertex_weights(&tet, emb[v], bary + 4 * v, joints + 4 * v, weights + 4 * v);
            }
        }
        int mesh = add_mesh(d, ti.name, ti.kind, ti.rest_positions, nrm, n, ti.triangles, ti.triangle_count, joints,
                            weights);
        free(nrm);
        cJSON *node = add_node(d, ti.name);
        if (node) {
            cJSON_AddNumberToObject(node, "mesh", mesh);
            cJSON_AddNumberToObject(node, "skin", 0);
        }
        cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber(cJSON_GetArraySize(d->nodes) - 1));
    }
    return 0;
}

/* Joint nodes 0..J-1 at their rest frames (relative to the parent), and the skin. */
static void add_skeleton(gl_doc *d, const pose_rig *rig, cJSON *scene_nodes)
{
    size_t nj = pose_rig_joint_count(rig);
    cJSON **nodes = calloc(nj ? nj : 1, sizeof *nodes);
    float *ibm = calloc(16 * (nj ? nj : 1), sizeof *ibm);
    cJSON *skin_joints = cJSON_CreateArray();
    if (!nodes || !ibm || !skin_joints) {
        d->oom = 1;
        free(nodes);
        free(ibm);
        cJSON_Delete(skin_joints);
        return;
    }
    for (size_t j = 0; j < nj; j++) {
        pose_joint_info ji;
        pose_rig_joint_info(rig, (int)j, &ji);
        cJSON *n = nodes[j] = add_node(d, ji.name);
        if (!n)
            break;
        double q[4], t[3];
        for (int k = 0; k < 4; k++)
            q[k] = ji.rest_local.rotation[k];
        for (int k = 0; k < 3; k++)
            t[k] = ji.rest_local.translation[k];
        cJSON_AddItemToObject(n, "rotation", cJSON_CreateDoubleArray(q, 4));
        cJSON_AddItemToObject(n, "translation", cJSON_CreateDoubleArray(t, 3));
        if (ji.parent < 0)
            cJSON_AddItemToArray(scene_nodes, cJSON_CreateNumber((double)j));
        else {
            cJSON *children = cJSON_GetObjectItem(nodes[ji.parent], "children");
            if (!children)
                children = cJSON_AddArrayToObject(nodes[ji.parent], "children");
            cJSON_AddItemToArray(children, cJSON_CreateNumber((double)j));
        }
        cJSON_AddItemToArray(skin_joints, cJSON_CreateNumber((double)j));
        /* inverse bind matrix: inverse(rest_model), column-major */
        const float *r = ji.rest_model.rotation, *p = ji.rest_model.translation;
        float x = r[0], y = r[1], z = r[2], w = r[3];
        float m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                         {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                         {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        float *o = ibm + 16 * j;
        for (int c = 0; c < 3; c++) /* column c of R^T is row c of R */
            for (int rr = 0; rr < 3; rr++)
                o[4 * c + rr] = m[c][rr];
        for (int rr = 0; rr < 3; rr++)
            o[12 + rr] = -(m[0][rr] * p[0] + m[1][rr] * p[1] + m[2][rr] * p[2]);
        o[15] = 1.0f;
    }
    cJSON *skins = cJSON_AddArrayToObject(d->root, "skins"), *skin = cJSON_CreateObject();
    if (!skins || !skin || !cJSON_AddItemToArray(skins, skin)) {
        cJSON_Delete(skin);
        cJSON_Delete(skin_joints);
        d->oom = 1;
    } else {
        cJSON_AddStringToObject(skin, "name", "pose skeleton");
        cJSON_AddItemToObject(skin, "joints", skin_joints);
        cJSON_AddNumberToObject(skin, "inverseBindMatrices", add_accessor(d, ibm, nj, GL_FLOAT, "MAT4", 0));
    }
    free(nodes);
    free(ibm);
}

static void add_channel(gl_doc *d, cJSON *samplers, cJSON *channels, int input, int output, size_t node,
                        const char *path)
{
    cJSON *s = cJSON_CreateObject(), *c = cJSON_CreateObject(), *target;
    if (!s || !c || !cJSON_AddItemToArray(samplers, s)) {
        cJSON_Delete(s);
        cJSON_Delete(c);
        d->oom = 1;
        return;
    }
    cJSON_AddNumberToObject(s, "input", input);
    cJSON_AddNumberToObject(s, "output", output);
    cJSON_AddStringToObject(s, "interpolation", "LINEAR");
    if (!cJSON_AddItemToArray(channels, c) || !(target = cJSON_AddObjectToObject(c, "target"))) {
        d->oom = 1;
        return;
    }
    cJSON_AddNumberToObject(c, "sampler", cJSON_GetArraySize(samplers) - 1);
    cJSON_AddNumberToObject(target, "node", (double)node);
    cJSON_AddStringToObject(target, "path", path);
}

static void add_animation(gl_doc *d, const ex_gltf_session *s)
{
    cJSON *anims = cJSON_AddArrayToObject(d->root, "animations"), *anim = cJSON_CreateObject(), *samplers,
          *channels;
    if (!anims || !anim || !cJSON_AddItemToArray(anims, anim) || !cJSON_AddStringToObject(anim, "name", "session") ||
        !(samplers = cJSON_AddArrayToObject(anim, "samplers")) || !(channels = cJSON_AddArrayToObject(anim, "channels"))) {
        d->oom = 1;
        return;
    }
    int input = add_accessor(d, s->times, s->frames, GL_FLOAT, "SCALAR", 0);
    float *buf = malloc(s->frames * 4 * sizeof *buf + 1);
    if (!buf) {
        d->oom = 1;
        return;
    }
    for (size_t j = 0; j < s->joints; j++) {
        pose_joint_info ji;
        pose_rig_joint_info(s->rig, (int)j, &ji);
        for (size_t f = 0; f < s->frames; f++)
            memcpy(buf + 4 * f, s->rotation + (f * s->joints + j) * 4, 4 * sizeof *buf);
        add_channel(d, samplers, channels, input, add_accessor(d, buf, s->frames, GL_FLOAT, "VEC4", 0), j,
                    "rotation");
        if (ji.parent < 0) {
            for (size_t f = 0; f < s->frames; f++)
                memcpy(buf + 3 * f, s->translation + (f * s->joints + j) * 3, 3 * sizeof *buf);
            add_channel(d, samplers, channels, input, add_accessor(d, buf, s->frames, GL_FLOAT, "VEC3", 0), j,
                        "translation");
        }
    }
    free(buf);
}

int ex_gltf_session_write(const ex_gltf_session *s, const char *path, char *err, size_t err_size)
{
    if (s->frames == 0) {
        snprintf(err, err_size, "%s: the session has no frames", path);
        return -1;
    }
    gl_doc d;
    int rc = -1;
    cJSON *scene_nodes = cJSON_CreateArray();
    if (!scene_nodes || doc_init(&d) < 0) {
        cJSON_Delete(scene_nodes);
        doc_free(&d);
        snprintf(err, err_size, "%s: out of memory", path);
        return -1;
    }
    add_materials(&d);
    add_skeleton(&d, s->rig, scene_nodes); /* joint nodes first: node j is joint j */
    if (add_skinned_meshes(&d, s->rig, scene_nodes, err, err_size) < 0) {
        cJSON_Delete(scene_nodes);
        doc_free(&d);
        return -1;
    }
    add_animation(&d, s);
    cJSON *scenes = cJSON_AddArrayToObject(d.root, "scenes"), *scene = cJSON_CreateObject();
    if (scenes && scene && cJSON_AddItemToArray(scenes, scene)) {
        cJSON_AddStringToObject(scene, "name", "session");
        cJSON_AddItemToObject(scene, "nodes", scene_nodes);
        cJSON_AddNumberToObject(d.root, "scene", 0);
        rc = doc_write(&d, path, err, err_size);
    } else {
        cJSON_Delete(scene);
        cJSON_Delete(scene_nodes);
        snprintf(err, err_size, "%s: out of memory", path);
    }
    doc_free(&d);
    return rc;
}
