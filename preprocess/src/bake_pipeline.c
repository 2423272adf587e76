/* SPDX-License-Identifier: Apache-2.0 */
#include "bake_pipeline.h"

#include "mesh_io.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

/* Expected share of the bake's time per stage, for the overall fraction
 * shown with the progress line (measured on the shared body). */
static const double stage_share[PP_STAGE_COUNT] = {0.02, 0.04, 0.02, 0.08, 0.35, 0.10, 0.37, 0.02};

const char *pp_bake_stage_name(pp_bake_stage s)
{
    static const char *names[PP_STAGE_COUNT] = {"load",    "rig",     "voxelize", "tetrahedralize",
                                                "weights", "mapping", "cor",      "write"};
    return (unsigned)s < PP_STAGE_COUNT ? names[s] : "?";
}

typedef struct stage_clock {
    const pp_bake_options *opt;
    pp_bake_report *rep;
    pp_bake_stage stage;
    double start;
} stage_clock;

static double share_before(pp_bake_stage s)
{
    double f = 0;
    for (int i = 0; i < (int)s; i++)
        f += stage_share[i];
    return f;
}

static void stage_begin(stage_clock *c, pp_bake_stage s)
{
    c->stage = s;
    c->start = pp_now_s();
    if (c->opt->progress)
        c->opt->progress(s, 0, share_before(s), c->opt->user);
}

static void stage_end(stage_clock *c)
{
    c->rep->seconds[c->stage] = pp_now_s() - c->start;
    if (c->opt->progress)
        c->opt->progress(c->stage, 1, share_before(c->stage) + stage_share[c->stage], c->opt->user);
}

static int overlaps(const float alo[3], const float ahi[3], const float blo[3], const float bhi[3])
{
    for (int k = 0; k < 3; k++)
        if (ahi[k] < blo[k] || bhi[k] < alo[k])
            return 0;
    return 1;
}

/* Everything a bake holds; freed in one place. */
typedef struct bake_state {
    pp_mesh skin;
    pp_mesh *bones;       /* opt->bone_count */
    int *bone_joint;      /* joint or -1 (soft) */
    pp_mesh *organs;
    pp_mesh *rig_bones;   /* shallow copies of the template's bones, for voxelizing */
    uint16_t *rig_labels;
    size_t rig_bone_count;
    pp_voxels vox;
    pp_tetmesh tet;
    pp_weights w;
    pp_tetmesh rigid;      /* shallow copy of tet with rigid_labels */
    uint16_t *rigid_labels;
    pp_tet_hash *hash;
    uint32_t **emb_tet;   /* per tissue */
    float **emb_bary;
    float *cor;
    pose_joint_desc *joints;
    pose_joint_clinical *clinical; /* NULL when the template has no clinical data */
    pose_tissue_desc *tissues;
    pose_fem_coupling *couplings;  /* the template's, resolved (NULL: none) */
    size_t coupling_count;
    pose_fem_soft_coupling *soft_couplings; /* its soft-soft ones (NULL: none) */
    size_t soft_coupling_count;
} bake_state;

static void bake_state_free(bake_state *s, const pp_bake_options *o, size_t tissue_count)
{
    pp_mesh_free(&s->skin);
    for (size_t i = 0; s->bones && i < o->bone_count; i++)
        pp_mesh_free(&s->bones[i]);
    for (size_t i = 0; s->organs && i < o->organ_count; i++)
        pp_mesh_free(&s->organs[i]);
    free(s->bones);
    free(s->bone_joint);
    free(s->organs);
    free(s->rig_bones);
    free(s->rig_labels);
    pp_voxels_free(&s->vox);
    pp_tetmesh_free(&s->tet);
    pp_weights_free(&s->w);
    pp_tet_hash_free(s->hash);
    free(s->rigid_labels);
    for (size_t i = 0; i < tissue_count; i++) {
        if (s->emb_tet)
            free(s->emb_tet[i]);
        if (s->emb_bary)
            free(s->emb_bary[i]);
    }
    free(s->emb_tet);
    free(s->emb_bary);
    free(s->cor);
    free(s->joints);
    free(s->clinical);
    free(s->tissues);
    free(s->couplings);
    free(s->soft_couplings);
}

static int load_meshes(const pp_bake_options *o, bake_state *s, pp_bake_report *rep, char *err,
                       size_t n)
{
    int rc = pp_template_load(o->template_path, &rep->tmpl, err, n);
    if (rc < 0)
        return rc;
    rc = pp_mesh_load(o->skin_path, &s->skin, err, n);
    if (rc < 0)
        return rc;
    s->bones = calloc(o->bone_count ? o->bone_count : 1, sizeof *s->bones);
    s->bone_joint = calloc(o->bone_count ? o->bone_count : 1, sizeof *s->bone_joint);
    s->organs = calloc(o->organ_count ? o->organ_count : 1, sizeof *s->organs);
    if (!s->bones || !s->bone_joint || !s->organs)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    float slo[3], shi[3];
    pp_mesh_bounds(&s->skin, slo, shi);
    for (size_t i = 0; i < o->bone_count; i++) {
        rc = pp_mesh_load(o->bone_paths[i], &s->bones[i], err, n);
        if (rc < 0)
            return rc;
        for (size_t k = 0; k < i; k++)
            if (strcmp(s->bones[k].name, s->bones[i].name) == 0)
                return pp_fail(err, n, POSE_ERR_INVALID_ARGUMENT,
                            "%s: a bone named '%s' was already given (%s); bone names are file "
                            "stems and must be unique",
                            o->bone_paths[i], s->bones[i].name, o->bone_paths[k]);
        float lo[3], hi[3];
        pp_mesh_bounds(&s->bones[i], lo, hi);
        if (!overlaps(lo, hi, slo, shi))
            return pp_fail(err, n, POSE_ERR_INVALID_DATA,
                        "%s: bone '%s' lies entirely outside the skin %s (are both in the same "
                        "frame and units?)",
                        o->bone_paths[i], s->bones[i].name, o->skin_path);
        s->bone_joint[i] = pp_template_joint_of_bone(&rep->tmpl, s->bones[i].name);
        rep->soft_bones += s->bone_joint[i] < 0;
    }
    for (size_t i = 0; i < o->organ_count; i++) {
        rc = pp_mesh_load(o->organ_paths[i], &s->organs[i], err, n);
        if (rc < 0)
            return rc;
    }
    return POSE_OK;
}

static int build_tissues(const pp_bake_options *o, bake_state *s, pp_bake_report *rep, char *err,
                         size_t n)
{
    size_t nt = 1 + o->bone_count + o->organ_count;
    rep->tissues = calloc(nt, sizeof *rep->tissues);
    s->emb_tet = calloc(nt, sizeof *s->emb_tet);
    s->emb_bary = calloc(nt, sizeof *s->emb_bary);
    s->tissues = calloc(nt, sizeof *s->tissues);
    if (!rep->tissues || !s->emb_tet || !s->emb_bary || !s->tissues)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    rep->tissue_count = nt;
    /* Bones embed in tets that move rigidly with their joint: labelled with
     * it and with weight exactly 1 at all four corners. A bone tet touching
     * another bone (a shared, reassigned corner) would bend the bone. */
    s->rigid_labels = malloc((s->tet.tet_count ? s->tet.tet_count : 1) * sizeof *s->rigid_labels);
    if (!s->rigid_labels)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t t = 0; t < s->tet.tet_count; t++) {
        uint16_t lab = s->tet.labels[t];
        for (int c = 0; lab && c < 4; c++)
            if (pp_weights_get(&s->w, s->tet.tets[4 * t + c], lab - 1u) != 1.0f)
                lab = 0;
        s->rigid_labels[t] = lab;
    }
    s->rigid = s->tet;
    s->rigid.labels = s->rigid_labels;
    char herr[256];
    int rc = pp_tet_hash_build(&s->rigid, 0, &s->hash, herr, sizeof herr);
    if (rc < 0)
        return pp_fail(err, n, rc, "%s", herr);
    int threads = o->threads > 0 ? o->threads : 1;
    for (size_t t = 0; t < nt; t++) {
        const pp_mesh *m;
        pose_tissue_kind kind;
        int joint = -1;
        if (t == 0) {
            m = &s->skin, kind = POSE_TISSUE_SKIN;
        } else if (t <= o->bone_count) {
            m = &s->bones[t - 1], kind = POSE_TISSUE_BONE, joint = s->bone_joint[t - 1];
        } else {
            m = &s->organs[t - 1 - o->bone_count], kind = POSE_TISSUE_ORGAN;
        }
        for (size_t k = 0; k < t; k++)
            if (strcmp(rep->tissues[k].name, m->name) == 0)
                return pp_fail(err, n, POSE_ERR_INVALID_ARGUMENT,
                            "two tissues are named '%s' (names are file stems; rename one file)",
                            m->name);
        pp_bake_tissue *bt = &rep->tissues[t];
        snprintf(bt->name, sizeof bt->name, "%s", m->name);
        bt->kind = kind;
        bt->joint = joint;
        s->emb_tet[t] = malloc((m->vertex_count ? m->vertex_count : 1) * sizeof(uint32_t));
        s->emb_bary[t] = malloc((m->vertex_count ? m->vertex_count : 1) * 4 * sizeof(float));
        if (!s->emb_tet[t] || !s->emb_bary[t])
            return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        pp_embed_report er = {0};
        /* A bone follows its own bone's tets when they are within two voxels. */
        double reach = 2.0 * rep->voxel_mm * 1e-3;
        rc = pp_embed_points(s->hash, m->positions, m->vertex_count, joint >= 0 ? joint + 1 : -1,
                             reach, threads, s->emb_tet[t], s->emb_bary[t], &er);
        if (rc < 0)
            return pp_fail(err, n, rc, "mapping '%s' failed", m->name);
        bt->vertices = er.vertices;
        bt->outside = er.outside;
        bt->max_distance = er.max_distance;
        bt->label_fallback = er.label_fallback;
        rep->mapping.vertices += er.vertices;
        rep->mapping.outside += er.outside;
        rep->mapping.label_fallback += er.label_fallback;
        rep->mapping.max_distance = fmax(rep->mapping.max_distance, er.max_distance);
        rep->mapping.seconds += er.seconds;
        s->tissues[t] = (pose_tissue_desc){bt->name,         kind,          joint,
                                           m->vertex_count,  m->positions,  m->triangle_count,
                                           m->triangles,     s->emb_tet[t], s->emb_bary[t]};
    }
    return POSE_OK;
}

/* The rig's clinical section from the bake's clinical fit (none when the
 * template has no "clinical" object), and a note for the metadata naming
 * the largest neutral offset. Returns the number of joints with clinical
 * data, or -1 when out of memory. */
static int clinical_desc(const pp_bake_report *rep, bake_state *s, char *note, size_t note_size)
{
    size_t nj = rep->tmpl.joint_count, count = 0, big = 0;
    for (size_t j = 0; j < nj; j++)
        if ((rep->clinical[j].c.flags & POSE_CLINICAL_DEFINED) &&
            (count++ == 0 || rep->clinical[j].neutral_deg > rep->clinical[big].neutral_deg))
            big = j;
    if (count == 0)
        return 0;
    s->clinical = calloc(nj, sizeof *s->clinical);
    if (!s->clinical)
        return -1;
    for (size_t j = 0; j < nj; j++)
        s->clinical[j] = rep->clinical[j].c;
    snprintf(note, note_size,
             "; neutral posture and clinical axes for %zu joints (largest neutral offset %s %.1f deg)",
             count, rep->tmpl.joints[big].name, rep->clinical[big].neutral_deg);
    return (int)count;
}

static int write_rig(const pp_bake_options *o, bake_state *s, pp_bake_report *rep, char *err,
                     size_t n)
{
    const pp_template *t = &rep->tmpl;
    s->joints = calloc(t->joint_count, sizeof *s->joints);
    if (!s->joints)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t j = 0; j < t->joint_count; j++) {
        const pp_template_joint *tj = &t->joints[j];
        pose_joint_desc *d = &s->joints[j];
        d->name = tj->name;
        d->parent = tj->parent;
        memcpy(d->rest_model.rotation, rep->fits[j].rotation, sizeof d->rest_model.rotation);
        for (int k = 0; k < 3; k++)
            d->rest_model.translation[k] = (float)rep->fits[j].centre[k];
        d->limit_flags = tj->limit_flags;
        d->limit_order = tj->limit_order;
        memcpy(d->limit_min_deg, tj->limit_min_deg, sizeof d->limit_min_deg);
        memcpy(d->limit_max_deg, tj->limit_max_deg, sizeof d->limit_max_deg);
    }
    char meta[1024], neutral[256] = "", coupled[128] = "", soft[96] = "";
    int clinical = clinical_desc(rep, s, neutral, sizeof neutral);
    if (clinical < 0)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    if (!o->no_fem && t->coupling_count) {
        int rc = pp_bake_couplings(t, s->bones, s->bone_joint, o->bone_count, &s->tet,
                                   &s->couplings, &s->coupling_count, err, n);
        if (rc < 0)
            return rc;
        rep->coupled_nodes = s->coupling_count;
        snprintf(coupled, sizeof coupled, "; %zu nodes coupled to bones (%zu template couplings)",
                 s->coupling_count, t->coupling_count);
        rc = pp_bake_soft_couplings(t, s->tissues, rep->tissue_count, &s->tet, &s->soft_couplings,
                                    &s->soft_coupling_count, err, n);
        if (rc < 0)
            return rc;
        rep->soft_coupled_nodes = s->soft_coupling_count;
        if (s->soft_coupling_count)
            snprintf(soft, sizeof soft, "; %zu soft-soft couplings", s->soft_coupling_count);
    }
    snprintf(meta, sizeof meta,
             "pose-bake %s; template %s (%s); skin %s; %zu bones; voxel %.2f mm; backend %s; "
             "K %u; %zu tet vertices, %zu tets%s%s%s",
             pose_version_string(), t->name, o->template_path, o->skin_path, o->bone_count,
             (double)rep->voxel_mm, pp_tet_backend_name(o->backend), s->w.influences,
             s->tet.vertex_count, s->tet.tet_count, neutral, coupled, soft);
    /* POSE_FEM simulates the rig's own tets (bone labels rigid): all it
     * needs stored is the soft tissue's material. */
    const pose_fem_material fem = {
        (float)PP_BAKE_FEM_YOUNG,
        (float)(o->fem_poisson > 0.0 ? o->fem_poisson : PP_BAKE_FEM_POISSON),
        (float)PP_BAKE_FEM_DENSITY};
    pose_rig_desc desc = {t->joint_count,     s->joints,     s->tet.vertex_count,
                          s->tet.positions,   s->tet.tet_count, s->tet.tets,
                          s->tet.labels,      s->w.influences, s->w.joints,
                          s->w.weights,       s->cor,        rep->tissue_count,
                          s->tissues,         meta,          s->clinical,
                          o->no_fem ? NULL : &fem, o->volume_count, o->volumes,
                          s->coupling_count,  s->couplings,
                          s->soft_coupling_count, s->soft_couplings};
    /* Write beside the target, then rename: a reader never sees half a rig. */
    size_t len = strlen(o->output_path) + 32;
    char *tmp = malloc(len);
    if (!tmp)
        return pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
    snprintf(tmp, len, "%s.tmp%ld", o->output_path, (long)getpid());
    pose_status st = pose_rig_write_file(&desc, tmp);
    if (st != POSE_OK) {
        int rc = pp_fail(err, n, st, "%s: writing the rig failed: %s", o->output_path,
                      pose_last_error());
        unlink(tmp);
        free(tmp);
        return rc;
    }
    if (rename(tmp, o->output_path) != 0) {
        int rc = pp_fail(err, n, POSE_ERR_IO, "%s: cannot move the finished rig into place: %s",
                      o->output_path, strerror(errno));
        unlink(tmp);
        free(tmp);
        return rc;
    }
    free(tmp);
    FILE *f = fopen(o->output_path, "rb");
    if (f) {
        fseek(f, 0, SEEK_END);
        long sz = ftell(f);
        rep->rig_bytes = sz > 0 ? (size_t)sz : 0;
        fclose(f);
    }
    return POSE_OK;
}

int pp_bake(const pp_bake_options *o, pp_bake_report *rep, char *err, size_t n)
{
    memset(rep, 0, sizeof *rep);
    if (!o || !o->skin_path || !o->template_path || !o->output_path || (o->bone_count && !o->bone_paths))
        return pp_fail(err, n, POSE_ERR_INVALID_ARGUMENT,
                    "bake: skin, template and output are required");
    if (o->bone_count == 0)
        return pp_fail(err, n, POSE_ERR_INVALID_ARGUMENT, "bake: no bone meshes given");
    if (!pp_tet_backend_available(o->backend))
        return pp_fail(err, n, POSE_ERR_UNSUPPORTED,
                    "bake: the %s backend is not built in (configure with POSE_WITH_TETGEN=ON "
                    "and libtet1.5-dev)",
                    pp_tet_backend_name(o->backend));
    double t0 = pp_now_s();
    bake_state s;
    memset(&s, 0, sizeof s);
    stage_clock clk = {o, rep, PP_STAGE_LOAD, 0};
    int threads = o->threads > 0 ? o->threads : 1;
    int rc;

    stage_begin(&clk, PP_STAGE_LOAD);
    rc = load_meshes(o, &s, rep, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_RIG);
    rep->fits = calloc(rep->tmpl.joint_count, sizeof *rep->fits);
    if (!rep->fits) {
        rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    rc = pp_rig_fit(&rep->tmpl, s.bones, o->bone_count, rep->fits, err, n);
    if (rc < 0)
        goto done;
    rep->clinical = calloc(rep->tmpl.joint_count, sizeof *rep->clinical);
    if (!rep->clinical) {
        rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    rc = pp_clinical_fit(&rep->tmpl, rep->fits, rep->clinical, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_VOXELIZE);
    s.rig_bones = calloc(o->bone_count, sizeof *s.rig_bones);
    s.rig_labels = calloc(o->bone_count, sizeof *s.rig_labels);
    if (!s.rig_bones || !s.rig_labels) {
        rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < o->bone_count; i++)
        if (s.bone_joint[i] >= 0) {
            s.rig_bones[s.rig_bone_count] = s.bones[i]; /* shallow: owned by s.bones */
            s.rig_labels[s.rig_bone_count++] = (uint16_t)s.bone_joint[i];
        }
    double mm = o->resolution_mm > 0 ? o->resolution_mm : PP_BAKE_DEFAULT_RESOLUTION_MM;
    rep->voxel_mm = (float)mm;
    rc = pp_voxelize(&s.skin, s.rig_bones, s.rig_labels, s.rig_bone_count, (float)(mm * 1e-3),
                     &s.vox, &rep->voxels, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_TETRAHEDRALIZE);
    pp_tet_options to = {.backend = o->backend, .target_vertices = o->target_vertices};
    rc = pp_tetrahedralize(&s.vox, &s.skin, &to, &s.tet, &rep->quality, err, n);
    if (rc < 0)
        goto done;
    pp_voxels_free(&s.vox); /* the largest buffer after the tets; not needed any more */
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_WEIGHTS);
    pp_weight_options wo = {.influences = o->influences};
    rc = pp_weights_compute(&s.tet, rep->tmpl.joint_count, &wo, &s.w, &rep->weights, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_MAPPING);
    rc = build_tissues(o, &s, rep, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_COR);
    if (!o->no_cor) {
        s.cor = malloc(3 * s.tet.vertex_count * sizeof *s.cor);
        if (!s.cor) {
            rc = pp_fail(err, n, POSE_ERR_OUT_OF_MEMORY, "out of memory for CoR");
            goto done;
        }
        pp_cor_options co = {.threads = threads, .tolerance = o->cor_step};
        rc = pp_cor_compute(&s.tet, &s.w, &co, s.cor, &rep->cor, err, n);
        if (rc < 0)
            goto done;
    }
    stage_end(&clk);

    stage_begin(&clk, PP_STAGE_WRITE);
    rc = write_rig(o, &s, rep, err, n);
    if (rc >= 0 && o->vtu_path)
        rc = pp_write_vtu(o->vtu_path, &s.tet, &s.w, &rep->tmpl, err, n);
    if (rc < 0)
        goto done;
    stage_end(&clk);
    rc = POSE_OK;
done:
    bake_state_free(&s, o, rep->tissue_count);
    rep->total_seconds = pp_now_s() - t0;
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        rep->peak_rss_mb = (double)ru.ru_maxrss / 1024.0;
    return rc;
}

void pp_bake_report_free(pp_bake_report *r)
{
    if (!r)
        return;
    pp_template_free(&r->tmpl);
    free(r->fits);
    free(r->clinical);
    free(r->tissues);
    memset(r, 0, sizeof *r);
}
