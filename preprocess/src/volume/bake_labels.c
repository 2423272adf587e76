/* SPDX-License-Identifier: Apache-2.0
 * pose-bake --labels: images -> surfaces + filtered template -> pp_bake. */
#include "bake_labels.h"

#include <cJSON.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "label_surface.h"
#include "labels_body.h"
#include "vol_nifti.h"

#include <pose/volume.h>

#define MAX_LABEL 65535

static char *read_text(const char *path, char *err, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        pp_fail(err, n, POSE_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = len >= 0 && len < (1L << 26) ? malloc((size_t)len + 1) : NULL;
    if (!buf || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        pp_fail(err, n, POSE_ERR_IO, "%s: cannot read (or larger than 64 MB)", path);
        free(buf);
        fclose(f);
        return NULL;
    }
    fclose(f);
    buf[len] = '\0';
    return buf;
}

/* labels.json: {"1": "spleen", ...}: ids 1..65535, names 1..63 bytes of
 * [A-Za-z0-9_-.] (they become file stems), unique. */
static int read_names(const char *path, char (**names)[PP_NAME_MAX], char *err, size_t n)
{
    char *text = read_text(path, err, n);
    if (!text)
        return POSE_ERR_IO;
    cJSON *root = cJSON_Parse(text);
    free(text);
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return pp_fail(err, n, POSE_ERR_FORMAT,
                       "%s: not a JSON object of label id -> name (e.g. {\"1\": \"spleen\"})",
                       path);
    }
    *names = calloc(MAX_LABEL + 1, sizeof **names);
    if (!*names) {
        cJSON_Delete(root);
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    int rc = 0;
    for (cJSON *e = root->child; e && rc == 0; e = e->next) {
        char *end;
        long id = strtol(e->string, &end, 10);
        if (*e->string == '\0' || *end || id < 1 || id > MAX_LABEL)
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA, "%s: key \"%s\": label ids are 1..%d",
                         path, e->string, MAX_LABEL);
        else if (!cJSON_IsString(e) || !e->valuestring[0] ||
                 strlen(e->valuestring) >= PP_NAME_MAX ||
                 strspn(e->valuestring, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                        "0123456789_-.") != strlen(e->valuestring))
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA,
                         "%s: label \"%s\": the name must be 1..63 characters of letters, digits, "
                         "'_', '-', '.'",
                         path, e->string);
        else if ((*names)[id][0])
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA, "%s: label %ld is named twice", path, id);
        else
            snprintf((*names)[id], PP_NAME_MAX, "%s", e->valuestring);
    }
    for (long a = 1; a <= MAX_LABEL && rc == 0; a++)
        for (long b = a + 1; (*names)[a][0] && b <= MAX_LABEL && rc == 0; b++)
            if ((*names)[b][0] && strcmp((*names)[a], (*names)[b]) == 0)
                rc = pp_fail(err, n, POSE_ERR_INVALID_DATA, "%s: labels %ld and %ld are both '%s'",
                             path, a, b, (*names)[a]);
    cJSON_Delete(root);
    return rc;
}

static int string_in(const cJSON *arr, const char *s)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, arr) if (cJSON_IsString(e) && strcmp(e->valuestring, s) == 0) return 1;
    return 0;
}

/* Drop bones not in the image from every list; drop joints left without
 * bones, and their descendants; write the result. */
static int filter_template(const char *in, const char *out, const uint8_t *present_name_set,
                           char (*names)[PP_NAME_MAX], char *absent, size_t absent_size, char *err,
                           size_t n)
{
    char *text = read_text(in, err, n);
    if (!text)
        return POSE_ERR_IO;
    cJSON *root = cJSON_Parse(text);
    free(text);
    cJSON *joints = root ? cJSON_GetObjectItemCaseSensitive(root, "joints") : NULL;
    if (!cJSON_IsArray(joints)) {
        cJSON_Delete(root);
        return pp_fail(err, n, POSE_ERR_FORMAT, "%s: not a skeleton template (no \"joints\" array)", in);
    }
    cJSON *dropped = cJSON_CreateArray();
    absent[0] = '\0';
    for (int i = 0; i < cJSON_GetArraySize(joints);) {
        cJSON *j = cJSON_GetArrayItem(joints, i);
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(j, "name");
        const cJSON *parent = cJSON_GetObjectItemCaseSensitive(j, "parent");
        static const char *lists[3] = {"bones", "contact", "parent_contact"};
        int nb = 0;
        for (int l = 0; l < 3; l++) {
            cJSON *arr = cJSON_GetObjectItemCaseSensitive(j, lists[l]);
            if (!cJSON_IsArray(arr))
                continue;
            for (int b = 0; b < cJSON_GetArraySize(arr);) {
                const cJSON *s = cJSON_GetArrayItem(arr, b);
                int have = 0;
                for (long id = 1; cJSON_IsString(s) && id <= MAX_LABEL && !have; id++)
                    have = present_name_set[id] && strcmp(names[id], s->valuestring) == 0;
                if (have)
                    b++;
                else
                    cJSON_DeleteItemFromArray(arr, b);
            }
            if (l == 0)
                nb = cJSON_GetArraySize(arr);
            else if (cJSON_GetArraySize(arr) == 0)
                cJSON_DeleteItemFromObjectCaseSensitive(j, lists[l]);
        }
        int orphan = cJSON_IsString(parent) && string_in(dropped, parent->valuestring);
        if ((nb == 0 || orphan) && cJSON_IsString(name)) {
            cJSON_AddItemToArray(dropped, cJSON_CreateString(name->valuestring));
            size_t l = strlen(absent);
            snprintf(absent + l, absent_size - l, "%s%s", l ? "," : "", name->valuestring);
            cJSON_DeleteItemFromArray(joints, i);
        } else {
            i++;
        }
    }
    cJSON_Delete(dropped);
    int rc = 0;
    if (cJSON_GetArraySize(joints) == 0)
        rc = pp_fail(err, n, POSE_ERR_INVALID_DATA,
                     "%s: none of the template's bones is in the label image (label names "
                     "must match the template's bone names)",
                     in);
    char *outtext = rc == 0 ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (rc == 0) {
        FILE *f = outtext ? fopen(out, "w") : NULL;
        if (!f || fputs(outtext, f) < 0 || fclose(f) != 0)
            rc = pp_fail(err, n, POSE_ERR_IO, "%s: cannot write the filtered template", out);
    }
    free(outtext);
    return rc;
}

static int push_path(char ***v, size_t *count, const char *s)
{
    char **nv = realloc(*v, (*count + 1) * sizeof **v);
    if (!nv)
        return -1;
    *v = nv;
    nv[*count] = strdup(s);
    return nv[(*count)++] ? 0 : -1;
}

/* A bone's surface one voxel out (6-neighbours of the label), where no
 * other bone lies within two voxels: the tets along a bone's surface then
 * move with it instead of blending with the soft tissue around (a bone
 * label should move rigidly to its last voxel), while the gap of a joint
 * (femoral head and acetabulum, discs) keeps its soft tissue. */
static void grow_bone(uint8_t *mask, const uint16_t *lab, const uint8_t *is_bone, uint16_t id,
                      int nx, int ny, int nz)
{
    const size_t sy = (size_t)nx, sz = (size_t)nx * ny;
    uint8_t *add = calloc(sz * nz, 1);
    if (!add)
        return;
    for (int k = 1; k < nz - 1; k++)
        for (int j = 1; j < ny - 1; j++)
            for (int i = 1; i < nx - 1; i++) {
                size_t v = k * sz + j * sy + (size_t)i;
                if (lab[v] == id || is_bone[lab[v]])
                    continue;
                if (lab[v + 1] != id && lab[v - 1] != id && lab[v + sy] != id && lab[v - sy] != id &&
                    lab[v + sz] != id && lab[v - sz] != id)
                    continue;
                int other = 0;
                for (int dk = -2; dk <= 2 && !other; dk++)
                    for (int dj = -2; dj <= 2 && !other; dj++)
                        for (int di = -2; di <= 2 && !other; di++) {
                            int a = i + di, b = j + dj, c = k + dk;
                            if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz)
                                continue;
                            uint16_t l = lab[(size_t)c * sz + (size_t)b * sy + (size_t)a];
                            other = l != id && is_bone[l];
                        }
                add[v] = !other;
            }
    for (size_t v = 0; v < sz * nz; v++)
        mask[v] |= add[v];
    free(add);
}

static int surface_to_obj(const uint8_t *mask, const pv_image *img, const double model[3][4],
                          int smooth, const char *name, const char *path, char *err, size_t n)
{
    pp_mesh m;
    int rc = pp_label_surface(mask, (int)img->nx, (int)img->ny, (int)img->nz, model, smooth, name, &m);
    if (rc < 0)
        return pp_fail(err, n, rc, "out of memory for the surface of '%s'", name);
    if (rc == 1)
        return 1;
    rc = pp_mesh_write_obj(&m, path);
    pp_mesh_free(&m);
    if (rc < 0)
        return pp_fail(err, n, POSE_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    return 0;
}

int pp_labels_prepare(const pp_labels_options *o, pp_bake_options *bake, pp_labels_report *r,
                      char *err, size_t n)
{
    memset(r, 0, sizeof *r);
    pv_image seg = {0}, ct = {0};
    char (*names)[PP_NAME_MAX] = NULL;
    uint16_t *lab = NULL;
    uint8_t *mask = NULL, *present = NULL, *is_bone = NULL;
    size_t *count = NULL;
    int rc;
    if (pv_nifti_read(o->labels_path, &seg, err, n) != 0)
        return POSE_ERR_FORMAT;
    rc = read_names(o->names_path, &names, err, n);
    if (rc < 0)
        goto done;
    if (o->volume_path) {
        if (pv_nifti_read(o->volume_path, &ct, err, n) != 0) {
            rc = POSE_ERR_FORMAT;
            goto done;
        }
        int same = ct.nx == seg.nx && ct.ny == seg.ny && ct.nz == seg.nz;
        for (int a = 0; a < 3 && same; a++)
            for (int c = 0; c < 4; c++)
                same &= fabs(ct.affine[a][c] - seg.affine[a][c]) < 1e-3 * (1 + fabs(seg.affine[a][c]));
        if (!same) {
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA,
                         "%s: the volume's grid (%lldx%lldx%lld and affine) differs from the "
                         "labels' %s (%lldx%lldx%lld); resample one onto the other first",
                         o->volume_path, (long long)ct.nx, (long long)ct.ny, (long long)ct.nz,
                         o->labels_path, (long long)seg.nx, (long long)seg.ny, (long long)seg.nz);
            goto done;
        }
    }
    const int nx = (int)seg.nx, ny = (int)seg.ny, nz = (int)seg.nz;
    const size_t nv = pv_image_voxels(&seg);
    r->dims[0] = nx, r->dims[1] = ny, r->dims[2] = nz;
    for (int a = 0; a < 3; a++)
        r->spacing_mm[a] = seg.spacing[a];
    lab = malloc(nv * sizeof *lab);
    mask = malloc(nv);
    present = calloc(MAX_LABEL + 1, 1);
    is_bone = calloc(MAX_LABEL + 1, 1);
    count = calloc(MAX_LABEL + 1, sizeof *count);
    if (!lab || !mask || !present || !is_bone || !count) {
        rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    for (size_t v = 0; v < nv; v++) {
        float x = seg.data[v];
        if (!(x >= 0 && x <= MAX_LABEL && x == floorf(x))) {
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA,
                         "%s: voxel %zu holds %g; labels are whole numbers 0..%d", o->labels_path,
                         v, (double)x, MAX_LABEL);
            goto done;
        }
        lab[v] = (uint16_t)x;
        count[lab[v]]++;
        r->labelled_voxels += lab[v] != 0;
    }
    for (long id = 1; id <= MAX_LABEL; id++)
        if (count[id]) {
            r->label_count++;
            present[id] = 1;
            if (!names[id][0])
                snprintf(names[id], PP_NAME_MAX, "label_%ld", id);
        }
    /* Body: labels, plus the CT above the threshold; the largest region; slices filled. */
    double thr = o->hu_threshold != 0 ? o->hu_threshold : PP_LABELS_DEFAULT_HU;
    for (size_t v = 0; v < nv; v++)
        mask[v] = lab[v] != 0 || (ct.data && ct.data[v] > thr);
    r->removed_voxels = pp_mask_largest_component(mask, nx, ny, nz);
    size_t filled = pp_mask_fill_slices(mask, nx, ny, nz);
    if (r->removed_voxels == (size_t)-1 || filled == (size_t)-1) {
        rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    r->filled_voxels = filled;
    for (size_t v = 0; v < nv; v++) {
        mask[v] |= lab[v] != 0;
        r->body_voxels += mask[v];
    }

    /* Scratch folder: skin, bones/, organs/, template.json. */
    const char *tmp = getenv("TMPDIR");
    snprintf(r->work_dir, sizeof r->work_dir, "%s/pose-bake-labels-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(r->work_dir)) {
        rc = pp_fail(err, n, POSE_ERR_IO, "%s: cannot create a scratch folder: %s", r->work_dir,
                     strerror(errno));
        r->work_dir[0] = '\0';
        goto done;
    }
    double model[3][4];
    pv_image_model_affine(&seg, model);
    int smooth = o->smooth == 0 ? PP_LABELS_DEFAULT_SMOOTH : o->smooth < 0 ? 0 : o->smooth;
    snprintf(r->skin_path, sizeof r->skin_path, "%s/skin.obj", r->work_dir);
    rc = surface_to_obj(mask, &seg, model, smooth, "skin", r->skin_path, err, n);
    if (rc != 0) {
        if (rc == 1)
            rc = pp_fail(err, n, POSE_ERR_INVALID_DATA, "%s: the image holds no body", o->labels_path);
        goto done;
    }
    snprintf(r->template_path, sizeof r->template_path, "%s/template.json", r->work_dir);
    rc = filter_template(o->template_path, r->template_path, present, names, r->absent_joints,
                         sizeof r->absent_joints, err, n);
    if (rc < 0)
        goto done;
    pp_template t;
    rc = pp_template_load(r->template_path, &t, err, n);
    if (rc < 0)
        goto done;
    for (long id = 1; id <= MAX_LABEL; id++)
        is_bone[id] = present[id] && pp_template_joint_of_bone(&t, names[id]) >= 0;
    /* Surfaces: bones of the template, other labels of some size as organs. */
    for (long id = 1; id <= MAX_LABEL && rc == 0; id++) {
        if (!present[id] || (!is_bone[id] && count[id] < PP_LABELS_MIN_VOXELS))
            continue;
        for (size_t v = 0; v < nv; v++)
            mask[v] = lab[v] == id;
        if (is_bone[id])
            grow_bone(mask, lab, is_bone, (uint16_t)id, nx, ny, nz);
        char path[512];
        snprintf(path, sizeof path, "%s/%s.obj", r->work_dir, names[id]);
        rc = surface_to_obj(mask, &seg, model, smooth, names[id], path, err, n);
        if (rc == 0 && push_path(is_bone[id] ? &r->bone_paths : &r->organ_paths,
                                 is_bone[id] ? &r->bone_count : &r->organ_count, path) < 0)
            rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    }
    /* Femoral heads: every ball joint whose bone and parent contact are labels. */
    for (size_t j = 0; j < t.joint_count && rc == 0 && r->head_count < 8; j++) {
        const pp_template_joint *tj = &t.joints[j];
        if (tj->rule != PP_FIT_BALL || tj->contact_count < 1 || tj->parent_contact_count < 1)
            continue;
        long a = 0, b = 0;
        for (long id = 1; id <= MAX_LABEL; id++) {
            if (present[id] && strcmp(names[id], tj->contact[0]) == 0)
                a = id;
            if (present[id] && strcmp(names[id], tj->parent_contact[0]) == 0)
                b = id;
        }
        if (!a || !b)
            continue;
        pp_labels_head *h = &r->heads[r->head_count];
        double c[3];
        h->points = pp_fit_contact_sphere(lab, nx, ny, nz, seg.spacing, (uint16_t)a, (uint16_t)b,
                                          12.0, c, &h->radius_mm);
        if (!h->points)
            continue;
        snprintf(h->joint, sizeof h->joint, "%s", tj->name);
        snprintf(h->label, sizeof h->label, "%s", names[a]);
        pv_image_voxel_to_world(&seg, c, h->centre_ras_mm);
        for (int k = 0; k < 3; k++)
            h->centre_model[k] = model[k][0] * c[0] + model[k][1] * c[1] + model[k][2] * c[2] + model[k][3];
        r->head_count++;
    }
    pp_template_free(&t);
    if (rc == 0) {
        /* The scan as the rig's rest image. */
        r->volume = calloc(1, sizeof *r->volume);
        r->volume_labels = malloc(nv * sizeof *r->volume_labels);
        if (ct.data)
            r->volume_intensity = malloc(nv * sizeof *r->volume_intensity);
        if (!r->volume || !r->volume_labels || (ct.data && !r->volume_intensity)) {
            rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        memcpy(r->volume_labels, lab, nv * sizeof *lab);
        if (ct.data)
            memcpy(r->volume_intensity, ct.data, nv * sizeof *ct.data);
        r->volume->name = "scan";
        r->volume->grid.nx = (uint32_t)nx, r->volume->grid.ny = (uint32_t)ny;
        r->volume->grid.nz = (uint32_t)nz;
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 4; c++)
                r->volume->grid.affine[a][c] = (float)model[a][c];
        r->volume->intensity = r->volume_intensity;
        r->volume->labels = r->volume_labels;
        bake->volume_count = 1;
        bake->volumes = r->volume;
        bake->skin_path = r->skin_path;
        bake->template_path = r->template_path;
        bake->bone_paths = (const char *const *)r->bone_paths;
        bake->bone_count = r->bone_count;
        bake->organ_paths = (const char *const *)r->organ_paths;
        bake->organ_count = r->organ_count;
    }
done:
    pv_image_free(&seg);
    pv_image_free(&ct);
    free(names), free(lab), free(mask), free(present), free(is_bone), free(count);
    return rc;
}

void pp_labels_cleanup(pp_labels_report *r)
{
    free(r->volume), free(r->volume_intensity), free(r->volume_labels);
    r->volume = NULL, r->volume_intensity = NULL, r->volume_labels = NULL;
    for (size_t i = 0; i < r->bone_count; i++)
        unlink(r->bone_paths[i]), free(r->bone_paths[i]);
    for (size_t i = 0; i < r->organ_count; i++)
        unlink(r->organ_paths[i]), free(r->organ_paths[i]);
    free(r->bone_paths), free(r->organ_paths);
    r->bone_paths = r->organ_paths = NULL;
    r->bone_count = r->organ_count = 0;
    if (r->work_dir[0]) {
        unlink(r->skin_path);
        unlink(r->template_path);
        rmdir(r->work_dir);
        r->work_dir[0] = '\0';
    }
}

static cJSON *vec3(const double v[3], double scale)
{
    const double a[3] = {v[0] * scale, v[1] * scale, v[2] * scale};
    return cJSON_CreateDoubleArray(a, 3);
}

char *pp_labels_report_json(const char *bake_json, const pp_labels_report *r,
                            const pp_bake_report *bake)
{
    cJSON *root = cJSON_Parse(bake_json);
    if (!root)
        return NULL;
    cJSON *v = cJSON_AddObjectToObject(root, "volume");
    cJSON_AddItemToObject(v, "dims", cJSON_CreateIntArray(r->dims, 3));
    cJSON_AddItemToObject(v, "spacing_mm", vec3(r->spacing_mm, 1));
    cJSON_AddNumberToObject(v, "labels", (double)r->label_count);
    cJSON_AddNumberToObject(v, "labelled_voxels", (double)r->labelled_voxels);
    cJSON_AddNumberToObject(v, "body_voxels", (double)r->body_voxels);
    cJSON_AddNumberToObject(v, "removed_voxels", (double)r->removed_voxels);
    cJSON_AddNumberToObject(v, "filled_voxels", (double)r->filled_voxels);
    cJSON_AddNumberToObject(v, "bones", (double)r->bone_count);
    cJSON_AddNumberToObject(v, "organs", (double)r->organ_count);
    cJSON_AddStringToObject(v, "absent_joints", r->absent_joints);
    cJSON *heads = cJSON_AddArrayToObject(v, "femoral_heads");
    for (size_t i = 0; i < r->head_count; i++) {
        const pp_labels_head *h = &r->heads[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "joint", h->joint);
        cJSON_AddStringToObject(o, "label", h->label);
        cJSON_AddItemToObject(o, "sphere_centre_ras_mm", vec3(h->centre_ras_mm, 1));
        cJSON_AddItemToObject(o, "sphere_centre_model_m", vec3(h->centre_model, 1));
        cJSON_AddNumberToObject(o, "radius_mm", h->radius_mm);
        cJSON_AddNumberToObject(o, "points", (double)h->points);
        int j = pp_template_find_joint(&bake->tmpl, h->joint);
        if (j >= 0 && bake->fits) {
            const double *c = bake->fits[j].centre;
            double d2 = 0;
            for (int k = 0; k < 3; k++)
                d2 += (c[k] - h->centre_model[k]) * (c[k] - h->centre_model[k]);
            cJSON_AddItemToObject(o, "joint_centre_model_m", vec3(c, 1));
            cJSON_AddNumberToObject(o, "joint_to_sphere_mm", 1e3 * sqrt(d2));
        }
        cJSON_AddItemToArray(heads, o);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}
