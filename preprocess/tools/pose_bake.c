/* SPDX-License-Identifier: Apache-2.0
 *
 * pose-bake: skin + bone meshes + skeleton template -> rig file.
 * Exit status: 0 success, 1 the bake failed (message on stderr), 2 usage.
 */
#include "bake_pipeline.h"
#ifdef POSE_HAVE_NIFTI
#include "bake_labels.h"
#endif
#include "pose_cli.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static void usage(FILE *f)
{
    fprintf(f,
            "usage: pose-bake --skin SKIN --bones DIR|FILE... --template TEMPLATE.json -o OUT.rig\n"
            "                 [--organs DIR|FILE...] [--resolution MM | --target-vertices N]\n"
            "                 [--backend lattice|tetgen] [-K N] [--threads N] [--no-cor] [--cor-step S]\n"
            "                 [--no-fem] [--fem-poisson NU]\n"
            "                 [--vtu FILE] [--json] [--report FILE] [--quiet]\n"
            "       pose-bake --labels SEG.nii.gz --label-names LABELS.json [--volume CT.nii.gz]\n"
            "                 [--hu-threshold HU] --template TEMPLATE.json -o OUT.rig [options above]\n"
            "\n"
            "Builds a rig for the pose runtime: fits the template's joints to the bones,\n"
            "voxelizes and tetrahedralizes the body, computes harmonic skinning weights,\n"
            "embeds every tissue vertex and computes centres of rotation.\n"
            "\n"
            "  --skin FILE            closed body surface (any format Assimp reads), metres\n"
            "  --bones DIR|FILE...    bone meshes; a directory means every mesh file in it;\n"
            "                         a mesh's name is its file stem (as the template names it)\n"
            "  --organs DIR|FILE...   extra tissues, embedded and deformed with the body\n"
            "  --template FILE        skeleton template (e.g. templates/full_body.json)\n"
            "  -o, --output FILE      rig to write (written to a temporary file, then renamed)\n"
            "  --resolution MM        voxel edge in millimetres (default %.0f)\n"
            "  --target-vertices N    tet vertex budget (the lattice coarsens to meet it)\n"
            "  --backend NAME         lattice (built in, default) or tetgen (AGPL build option)\n"
            "  -K, --influences N     weights kept per vertex, 1..8 (default 4)\n"
            "  --threads N            worker threads for mapping and CoR (default: cores)\n"
            "  --no-cor               skip centres of rotation\n"
            "  --cor-step S           CoR weight-bin step (default 1/128; smaller is closer to\n"
            "                         the direct formula and slower: 1/256 ~ 4x)\n"
            "  --no-fem               no fem section (the rig then has no POSE_FEM)\n"
            "  --fem-poisson NU       soft tissue's Poisson ratio for POSE_FEM (default %.2f)\n"
            "  --labels SEG.nii[.gz]  bake from a label image (NIfTI) instead of meshes: body =\n"
            "                         labels + CT above --hu-threshold (default -500), largest\n"
            "                         region, slices filled; bones = labels the template names\n"
            "  --label-names FILE     JSON {\"id\": \"name\"} (names match the template's bones)\n"
            "  --volume CT.nii[.gz]   the CT/MRI on the labels' grid (body threshold)\n"
            "  --vtu FILE             also write the tet mesh, labels and weights for ParaView\n"
            "  --json                 print the report as JSON on stdout\n"
            "  --report FILE          write the JSON report to FILE\n"
            "  --quiet                no progress line\n"
            "  --help, --version\n",
            PP_BAKE_DEFAULT_RESOLUTION_MM, PP_BAKE_FEM_POISSON);
}

typedef struct path_list {
    char **v;
    size_t n, cap;
} path_list;

static int push(path_list *l, const char *s)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 32;
        char **v = realloc(l->v, cap * sizeof *v);
        if (!v)
            return -1;
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n] = strdup(s);
    return l->v[l->n++] ? 0 : -1;
}

static void list_free(path_list *l)
{
    for (size_t i = 0; i < l->n; i++)
        free(l->v[i]);
    free(l->v);
}

static int is_mesh_file(const char *name)
{
    static const char *ext[] = {".obj", ".stl", ".ply", ".gltf", ".glb", ".fbx", ".off", ".dae", ".3ds"};
    const char *dot = strrchr(name, '.');
    if (!dot)
        return 0;
    for (size_t i = 0; i < sizeof ext / sizeof ext[0]; i++)
        if (strcasecmp(dot, ext[i]) == 0)
            return 1;
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A directory adds its mesh files (sorted, for reproducible bakes). */
static int add_path(path_list *l, const char *path, const char *what)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "pose-bake: %s %s: %s\n", what, path, strerror(errno));
        return -1;
    }
    if (!S_ISDIR(st.st_mode))
        return push(l, path);
    DIR *d = opendir(path);
    if (!d) {
        fprintf(stderr, "pose-bake: %s %s: %s\n", what, path, strerror(errno));
        return -1;
    }
    size_t first = l->n;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.' || !is_mesh_file(e->d_name))
            continue;
        size_t len = strlen(path) + strlen(e->d_name) + 2;
        char *full = malloc(len);
        if (!full) {
            closedir(d);
            return -1;
        }
        snprintf(full, len, "%s/%s", path, e->d_name);
        int rc = push(l, full);
        free(full);
        if (rc < 0) {
            closedir(d);
            return -1;
        }
    }
    closedir(d);
    if (l->n == first) {
        fprintf(stderr, "pose-bake: %s directory %s holds no mesh files\n", what, path);
        return -1;
    }
    qsort(l->v + first, l->n - first, sizeof *l->v, cmp_str);
    return 0;
}

typedef struct progress_state {
    int tty;
    double start;
} progress_state;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void on_progress(pp_bake_stage stage, int finished, double done, void *user)
{
    progress_state *p = user;
    if (!p->tty)
        return;
    double el = now_s() - p->start;
    char eta[32] = "";
    if (done > 0.02)
        snprintf(eta, sizeof eta, " ETA %.0f s", el * (1 - done) / done);
    fprintf(stderr, "\r\033[Kpose-bake: [%d/%d] %-15s %3.0f%%%s", (int)stage + 1, PP_STAGE_COUNT,
            pp_bake_stage_name(stage), 100 * done, finished && stage == PP_STAGE_COUNT - 1 ? "" : eta);
    if (finished && stage == PP_STAGE_COUNT - 1)
        fputc('\n', stderr);
    fflush(stderr);
}

static void print_summary(const pp_bake_report *r, const pp_bake_options *o)
{
    printf("pose-bake: wrote %s (%.1f MB) in %.2f s, peak memory %.0f MB\n", o->output_path,
           (double)r->rig_bytes / 1e6, r->total_seconds, r->peak_rss_mb);
    printf("stages:");
    for (int s = 0; s < PP_STAGE_COUNT; s++)
        printf(" %s %.2f s%s", pp_bake_stage_name((pp_bake_stage)s), r->seconds[s],
               s + 1 < PP_STAGE_COUNT ? "," : "\n");
    printf("tet mesh (%s, voxel %.1f mm): %zu vertices, %zu tets, dihedral %.1f..%.1f deg, "
           "radius-edge <= %.2f\n",
           pp_tet_backend_name(o->backend), (double)r->voxel_mm, r->quality.vertex_count,
           r->quality.tet_count, r->quality.min_dihedral_deg, r->quality.max_dihedral_deg,
           r->quality.max_radius_edge);
    printf("joints (centre in m, fit residual):\n");
    for (size_t j = 0; j < r->tmpl.joint_count; j++) {
        const pp_fit_joint *f = &r->fits[j];
        printf("  %-12s %-6s (%7.4f %7.4f %7.4f)  %zu pts  r %.1f mm  rms %.2f mm\n",
               r->tmpl.joints[j].name, pp_fit_rule_name(r->tmpl.joints[j].rule), f->centre[0],
               f->centre[1], f->centre[2], f->contact_points, f->radius_mm, f->residual_mm);
    }
    const pp_weight_report *w = &r->weights;
    printf("weights: %zu free + %zu bone vertices, %s factor nnz %zu; partition of unity "
           "|sum-1| <= %.1e (%s); range %.4f..%.4f",
           w->free_vertices, w->fixed_vertices, w->supernodal ? "supernodal" : "simplicial",
           w->factor_nnz, w->max_sum_error, w->max_sum_error < 1e-6 ? "ok" : "FAILED",
           w->min_weight, w->max_weight);
    if (w->clipped_entries) /* obtuse tets' positive entries, moved to the diagonal */
        printf(" (%zu obtuse-edge entries lumped for the maximum principle)", w->clipped_entries);
    double over = fmax(-w->min_weight, w->max_weight - 1);
    if (over > 1e-6)
        printf(" (outside [0,1] by %.2g; clamped and renormalized)", over);
    printf("; largest weight dropped by K: %.3g\n", w->max_dropped);
    if (w->floating_regions || w->empty_joints || w->conflict_vertices)
        printf("weights: %zu soft islands pinned (%zu vertices), %zu joints without bone tets, "
               "%zu vertices on two bones\n",
               w->floating_regions, w->floating_vertices, w->empty_joints, w->conflict_vertices);
    printf("mapping: %zu vertices, %zu outside the tet mesh (largest distance %.2f mm)\n",
           r->mapping.vertices, r->mapping.outside, r->mapping.max_distance * 1e3);
    for (size_t t = 0; t < r->tissue_count; t++)
        if (r->tissues[t].outside)
            printf("  %-14s %zu of %zu outside, up to %.2f mm\n", r->tissues[t].name,
                   r->tissues[t].outside, r->tissues[t].vertices, r->tissues[t].max_distance * 1e3);
    if (!o->no_cor)
        printf("cor: %zu vertices; %zu tets in %zu joint pairs, %zu bins x %zu vertex cells; "
               "%zu pair terms\n",
               r->cor.vertices_with_cor, r->cor.tets_used, r->cor.pairs, r->cor.bins,
               r->cor.cells, r->cor.evaluations);
}

int main(int argc, char **argv)
{
    pp_bake_options o = {0};
    const char *labels_path = NULL, *names_path = NULL, *volume_path = NULL;
    double hu = 0;
    path_list bones = {0}, organs = {0};
    int json = 0, quiet = 0, status = 2;
    const char *report_path = NULL;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    o.threads = cores > 0 ? (int)cores : 1;
    enum { OPT_BONES = POSE_CLI_LONG_ONLY, OPT_ORGANS, OPT_SKIN, OPT_TEMPLATE, OPT_VTU, OPT_REPORT,
           OPT_RESOLUTION, OPT_TARGET_VERTICES, OPT_BACKEND, OPT_THREADS, OPT_COR_STEP, OPT_NO_COR,
           OPT_NO_FEM, OPT_FEM_POISSON,
           OPT_JSON, OPT_QUIET, OPT_VERSION, OPT_LABELS, OPT_LABEL_NAMES, OPT_VOLUME, OPT_HU };
    static const struct option options[] = {
        {"skin", required_argument, NULL, OPT_SKIN},
        {"bones", required_argument, NULL, OPT_BONES},
        {"organs", required_argument, NULL, OPT_ORGANS},
        {"template", required_argument, NULL, OPT_TEMPLATE},
        {"output", required_argument, NULL, 'o'},
        {"resolution", required_argument, NULL, OPT_RESOLUTION},
        {"target-vertices", required_argument, NULL, OPT_TARGET_VERTICES},
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"influences", required_argument, NULL, 'K'},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"cor-step", required_argument, NULL, OPT_COR_STEP},
        {"no-cor", no_argument, NULL, OPT_NO_COR},
        {"no-fem", no_argument, NULL, OPT_NO_FEM},
        {"fem-poisson", required_argument, NULL, OPT_FEM_POISSON},
        {"vtu", required_argument, NULL, OPT_VTU},
        {"labels", required_argument, NULL, OPT_LABELS},
        {"label-names", required_argument, NULL, OPT_LABEL_NAMES},
        {"volume", required_argument, NULL, OPT_VOLUME},
        {"hu-threshold", required_argument, NULL, OPT_HU},
        {"json", no_argument, NULL, OPT_JSON},
        {"report", required_argument, NULL, OPT_REPORT},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"version", no_argument, NULL, OPT_VERSION},
        {"help", no_argument, NULL, 'h'},
        {0}};
    pose_cli cli;
    pose_cli_begin(&cli, "pose-bake", argc, argv, options);
    /* --bones and --organs take every argument up to the next option (shell globs). */
    path_list *list = NULL;
    double d;
    long n;
    for (int c; (c = pose_cli_next(&cli)) != POSE_CLI_END;) {
        if (c != POSE_CLI_ARGUMENT)
            list = NULL;
        switch (c) {
        case 'h':
            usage(stdout);
            status = 0;
            goto out;
        case OPT_VERSION:
            printf("pose-bake %s\n", pose_version_string());
            status = 0;
            goto out;
        case OPT_BONES:
        case OPT_ORGANS:
        case POSE_CLI_ARGUMENT: /* the option's value is its list's first path */
            if (c != POSE_CLI_ARGUMENT)
                list = c == OPT_BONES ? &bones : &organs;
            if (!list) {
                pose_cli_error(&cli, "unexpected argument '%s'", cli.value);
                goto out;
            }
            if (add_path(list, cli.value, list == &bones ? "bones" : "organs") < 0) {
                status = 1;
                goto out;
            }
            break;
        case OPT_SKIN:
            o.skin_path = cli.value;
            break;
        case OPT_TEMPLATE:
            o.template_path = cli.value;
            break;
        case 'o':
            o.output_path = cli.value;
            break;
        case OPT_VTU:
            o.vtu_path = cli.value;
            break;
        case OPT_REPORT:
            report_path = cli.value;
            break;
        case OPT_RESOLUTION:
            if (pose_cli_double(&cli, 0.2, 100, &d) < 0)
                goto out;
            o.resolution_mm = d;
            break;
        case OPT_TARGET_VERTICES:
            if (pose_cli_long(&cli, 100, 100000000, &n) < 0)
                goto out;
            o.target_vertices = (size_t)n;
            break;
        case OPT_BACKEND:
            if (pp_tet_backend_parse(cli.value, &o.backend) < 0) {
                pose_cli_error(&cli, "--backend is lattice or tetgen (got '%s')", cli.value);
                goto out;
            }
            break;
        case 'K':
            if (pose_cli_long(&cli, 1, PP_MAX_INFLUENCES, &n) < 0)
                goto out;
            o.influences = (unsigned)n;
            break;
        case OPT_THREADS:
            if (pose_cli_long(&cli, 1, 64, &n) < 0)
                goto out;
            o.threads = (int)n;
            break;
        case OPT_COR_STEP:
            if (pose_cli_double(&cli, 1e-5, 0.5, &d) < 0)
                goto out;
            o.cor_step = d;
            break;
        case OPT_NO_COR:
            o.no_cor = 1;
            break;
        case OPT_NO_FEM:
            o.no_fem = 1;
            break;
        case OPT_FEM_POISSON:
            if (pose_cli_double(&cli, 0.0, 0.4999, &d) < 0)
                goto out;
            o.fem_poisson = d;
            break;
        case OPT_LABELS:
            labels_path = cli.value;
            break;
        case OPT_LABEL_NAMES:
            names_path = cli.value;
            break;
        case OPT_VOLUME:
            volume_path = cli.value;
            break;
        case OPT_HU:
            if (pose_cli_double(&cli, -2000, 5000, &d) < 0)
                goto out;
            hu = d;
            break;
        case OPT_JSON:
            json = 1;
            break;
        case OPT_QUIET:
            quiet = 1;
            break;
        default: /* POSE_CLI_ERROR: reported */
            goto out;
        }
    }
    if (labels_path) {
#ifdef POSE_HAVE_NIFTI
        if (!names_path || !o.template_path || !o.output_path || o.skin_path || bones.n) {
            fprintf(stderr, "pose-bake: --labels needs --label-names, --template and -o, and "
                            "takes no --skin or --bones (see --help)\n");
            goto out;
        }
#else
        fprintf(stderr, "pose-bake: built without NIfTI support (libnifti2-dev): no --labels\n");
        goto out;
#endif
    } else if (names_path || volume_path) {
        fprintf(stderr, "pose-bake: --label-names and --volume go with --labels\n");
        goto out;
    } else if (!o.skin_path || !bones.n || !o.template_path || !o.output_path) {
        fprintf(stderr, "pose-bake: --skin, --bones, --template and -o are required (see --help)\n");
        goto out;
    }
    if (o.resolution_mm > 0 && o.target_vertices) {
        fprintf(stderr, "pose-bake: give --resolution or --target-vertices, not both\n");
        goto out;
    }
    if (o.target_vertices && o.resolution_mm == 0)
        o.resolution_mm = 4.0; /* a fine image for the lattice to coarsen from */
    o.bone_paths = (const char *const *)bones.v;
    o.bone_count = bones.n;
    o.organ_paths = (const char *const *)organs.v;
    o.organ_count = organs.n;
    progress_state ps = {!quiet && isatty(STDERR_FILENO), now_s()};
    o.progress = on_progress;
    o.user = &ps;

    pp_bake_report rep;
    char err[1024];
    int rc = 0;
#ifdef POSE_HAVE_NIFTI
    pp_labels_report lrep;
    memset(&lrep, 0, sizeof lrep);
    if (labels_path) {
        const pp_labels_options lo = {labels_path, names_path, volume_path, o.template_path, hu, 0};
        rc = pp_labels_prepare(&lo, &o, &lrep, err, sizeof err);
    }
    if (rc < 0)
        memset(&rep, 0, sizeof rep);
    else
#endif
        rc = pp_bake(&o, &rep, err, sizeof err);
    if (ps.tty && rc < 0)
        fputc('\n', stderr);
    if (rc < 0) {
        fprintf(stderr, "pose-bake: %s\n", err);
        status = 1;
    } else {
        status = 0;
        char *text = (json || report_path) ? pp_bake_report_json(&rep, &o) : NULL;
#ifdef POSE_HAVE_NIFTI
        if (text && labels_path) {
            char *merged = pp_labels_report_json(text, &lrep, &rep);
            free(text);
            text = merged;
        }
        if (labels_path && !json)
            for (size_t h = 0; h < lrep.head_count; h++)
                printf("femoral head %s (%s): sphere r %.1f mm at RAS (%.1f %.1f %.1f) mm\n",
                       lrep.heads[h].joint, lrep.heads[h].label, lrep.heads[h].radius_mm,
                       lrep.heads[h].centre_ras_mm[0], lrep.heads[h].centre_ras_mm[1],
                       lrep.heads[h].centre_ras_mm[2]);
#endif
        if (json && text)
            printf("%s\n", text);
        else if (!json)
            print_summary(&rep, &o);
        if (report_path) {
            FILE *f = fopen(report_path, "w");
            int bad = !f || !text;
            if (f) {
                bad |= fputs(text ? text : "", f) < 0;
                bad |= fclose(f) != 0;
            }
            if (bad) {
                fprintf(stderr, "pose-bake: %s: cannot write the report: %s\n", report_path,
                        strerror(errno));
                status = 1;
            }
        }
        free(text);
    }
    pp_bake_report_free(&rep);
#ifdef POSE_HAVE_NIFTI
    pp_labels_cleanup(&lrep);
#endif
out:
    list_free(&bones);
    list_free(&organs);
    return status;
}
