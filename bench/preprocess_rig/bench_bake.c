/* SPDX-License-Identifier: Apache-2.0
 *
 * Per-stage times of pose-bake on the shared body: wall and CPU seconds for
 * load, rig fit, voxelize, tetrahedralize, weights, mapping and CoR, plus
 * peak memory (getrusage). Each configuration runs in its own process so
 * peak memory is its own.
 *
 *   bench_preprocess_rig [--data DIR] [--template FILE] [--threads N]
 *                        [--tissue-vertices N] [--cor-check N] [--compare-backends MM]
 *                        CONFIG...
 *   CONFIG = MM (voxel edge, one lattice cell per voxel) or MM:VERTICES
 *            (voxel edge, lattice coarsened to a vertex budget)
 *
 * --tissue-vertices N maps N points (the tissue vertices repeated with a
 * sub-millimetre jitter) to measure mapping at the paper's 1.3 M scale.
 * --compare-backends MM bakes with the lattice and TetGen at MM, poses both
 * rigs alike and prints time, size, quality, weight bounds and the posed
 * skin difference.
 * --cor-check N compares the fast CoR with the direct formula on N random
 * tet vertices and prints the largest deviation.
 */
#include "bake_pipeline.h"
#include "mesh_io.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct clockpair {
    double wall, cpu;
} clockpair;

static clockpair now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (clockpair){(double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec,
                       (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec};
}

static void lap(const char *stage, clockpair *t, const char *detail)
{
    clockpair n = now();
    printf("  %-15s %8.2f s wall %8.2f s cpu   %s\n", stage, n.wall - t->wall, n.cpu - t->cpu, detail);
    fflush(stdout);
    *t = n;
}

static int die(const char *what, const char *err)
{
    fprintf(stderr, "bench_preprocess_rig: %s: %s\n", what, err);
    return 1;
}

static int run(const char *data, const char *tmpl_path, double mm, size_t target, int threads,
               size_t tissue_points, size_t cor_check)
{
    char err[1024], path[1200], detail[256];
    clockpair t0 = now(), t = t0;
    printf("voxel %.1f mm%s", mm, target ? "" : "\n");
    if (target)
        printf(", tet budget %zu vertices\n", target);

    /* load */
    pp_template tmpl;
    if (pp_template_load(tmpl_path, &tmpl, err, sizeof err) < 0)
        return die("template", err);
    pp_mesh skin;
    snprintf(path, sizeof path, "%s/anatomy/skin.obj", data);
    if (pp_mesh_load(path, &skin, err, sizeof err) < 0)
        return die("skin", err);
    snprintf(path, sizeof path, "%s/anatomy/bones", data);
    DIR *d = opendir(path);
    if (!d)
        return die(path, "cannot open");
    pp_mesh *bones = calloc(256, sizeof *bones);
    uint16_t *labels = calloc(256, sizeof *labels);
    size_t nb = 0, nv = skin.vertex_count;
    struct dirent *e;
    while ((e = readdir(d)) && nb < 256) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".obj"))
            continue;
        char bp[1500];
        snprintf(bp, sizeof bp, "%s/%s", path, e->d_name);
        if (pp_mesh_load(bp, &bones[nb], err, sizeof err) < 0)
            return die(bp, err);
        int j = pp_template_joint_of_bone(&tmpl, bones[nb].name);
        labels[nb] = (uint16_t)(j < 0 ? 0 : j);
        nv += bones[nb].vertex_count;
        nb++;
    }
    closedir(d);
    snprintf(detail, sizeof detail, "skin + %zu bones, %zu tissue vertices", nb, nv);
    lap("load", &t, detail);

    pp_fit_joint *fits = calloc(tmpl.joint_count, sizeof *fits);
    if (pp_rig_fit(&tmpl, bones, nb, fits, err, sizeof err) < 0)
        return die("rig", err);
    snprintf(detail, sizeof detail, "%zu joints", tmpl.joint_count);
    lap("rig", &t, detail);

    pp_voxels vox;
    pp_voxel_report vr;
    if (pp_voxelize(&skin, bones, labels, nb, (float)(mm * 1e-3), &vox, &vr, err, sizeof err) < 0)
        return die("voxelize", err);
    snprintf(detail, sizeof detail, "%d x %d x %d, %zu body voxels", vox.nx, vox.ny, vox.nz,
             vr.body_voxels);
    lap("voxelize", &t, detail);

    pp_tetmesh tet;
    pp_tet_quality q;
    pp_tet_options to = {.target_vertices = target};
    if (pp_tetrahedralize(&vox, &skin, &to, &tet, &q, err, sizeof err) < 0)
        return die("tetrahedralize", err);
    pp_voxels_free(&vox);
    snprintf(detail, sizeof detail, "%zu vertices, %zu tets", tet.vertex_count, tet.tet_count);
    lap("tetrahedralize", &t, detail);

    pp_weights w;
    pp_weight_report wr;
    if (pp_weights_compute(&tet, tmpl.joint_count, NULL, &w, &wr, err, sizeof err) < 0)
        return die("weights", err);
    snprintf(detail, sizeof detail,
             "assemble %.2f + factor %.2f + solve %.2f s, %s, factor nnz %zu, %zu free",
             wr.seconds_assemble, wr.seconds_factor, wr.seconds_solve,
             wr.supernodal ? "supernodal" : "simplicial", wr.factor_nnz, wr.free_vertices);
    lap("weights", &t, detail);

    /* Mapping: every tissue vertex, or tissue_points of them (repeated, jittered). */
    size_t np = tissue_points ? tissue_points : nv;
    float *pts = malloc(3 * np * sizeof *pts), *bary = malloc(4 * np * sizeof *bary);
    uint32_t *tt = malloc(np * sizeof *tt);
    if (!pts || !bary || !tt)
        return die("mapping", "out of memory");
    size_t k = 0;
    unsigned seed = 1;
    while (k < np)
        for (size_t m = 0; m <= nb && k < np; m++) {
            const pp_mesh *src = m == 0 ? &skin : &bones[m - 1];
            for (size_t v = 0; v < src->vertex_count && k < np; v++, k++)
                for (int c = 0; c < 3; c++) {
                    seed = seed * 1103515245u + 12345u;
                    double jitter = k < nv ? 0 : ((double)((seed >> 8) & 0xffff) / 65536.0 - 0.5) * 1e-3;
                    pts[3 * k + c] = src->positions[3 * v + c] + (float)jitter;
                }
        }
    clockpair tm = now();
    pp_tet_hash *h;
    if (pp_tet_hash_build(&tet, 0, &h, err, sizeof err) < 0)
        return die("mapping", err);
    double build_s = now().wall - tm.wall;
    pp_embed_report er = {0};
    pp_embed_points(h, pts, np, -1, 0, threads, tt, bary, &er);
    size_t buckets, entries;
    double cell;
    pp_tet_hash_stats(h, &buckets, &entries, &cell);
    snprintf(detail, sizeof detail,
             "%zu points, %zu outside (max %.1f mm); hash %.1f mm cells, %zu entries, built in %.2f s",
             np, er.outside, er.max_distance * 1e3, cell * 1e3, entries, build_s);
    lap("mapping", &t, detail);
    pp_tet_hash_free(h);

    float *cor = malloc(3 * tet.vertex_count * sizeof *cor);
    pp_cor_options co = {.threads = threads,
                         .tolerance = getenv("BENCH_COR_STEP") ? atof(getenv("BENCH_COR_STEP")) : 0,
                         .cell_tolerance = getenv("BENCH_COR_CELL") ? atof(getenv("BENCH_COR_CELL")) : 0};
    pp_cor_report cr;
    if (pp_cor_compute(&tet, &w, &co, cor, &cr, err, sizeof err) < 0)
        return die("cor", err);
    snprintf(detail, sizeof detail, "%zu vertices, %zu pairs, %zu bins, %zu cells, %.2g terms",
             cr.vertices_with_cor, cr.pairs, cr.bins, cr.cells, (double)cr.evaluations);
    lap("cor", &t, detail);

    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    clockpair end = now();
    if (cor_check) { /* accuracy: the direct formula on a random sample of vertices */
        uint32_t *sample = malloc(cor_check * sizeof *sample);
        float *ref = malloc(3 * cor_check * sizeof *ref);
        for (size_t i = 0; i < cor_check; i++) {
            seed = seed * 1103515245u + 12345u;
            sample[i] = (uint32_t)(((size_t)seed * 2654435761u) % tet.vertex_count);
        }
        pp_cor_naive_vertices(&tet, &w, 0.1, sample, cor_check, ref);
        double dev = 0;
        size_t worst = 0;
        for (size_t i = 0; i < cor_check; i++)
            for (int c = 0; c < 3; c++) {
                double dd = fabs((double)ref[3 * i + c] - cor[3 * (size_t)sample[i] + c]);
                if (dd > dev)
                    dev = dd, worst = i;
            }
        if (getenv("BENCH_DEBUG")) {
            size_t v = sample[worst];
            fprintf(stderr, "worst v %zu ref (%g %g %g) fast (%g %g %g) w:", v, ref[3 * worst],
                    ref[3 * worst + 1], ref[3 * worst + 2], cor[3 * v], cor[3 * v + 1], cor[3 * v + 2]);
            for (unsigned u = 0; u < w.influences; u++)
                fprintf(stderr, " %u:%g", w.joints[v * w.influences + u], w.weights[v * w.influences + u]);
            fprintf(stderr, "\n");
        }
        printf("  cor check       max deviation from the direct formula on %zu vertices: %.3f mm "
               "(%.1e of the 1.7 m body)\n", cor_check, dev * 1e3, dev / 1.705);
        free(sample), free(ref);
    }
    printf("  %-15s %8.2f s wall %8.2f s cpu   peak memory %.0f MB\n", "total", end.wall - t0.wall,
           end.cpu - t0.cpu, (double)ru.ru_maxrss / 1024.0);
    fflush(stdout);
    free(cor), free(pts), free(bary), free(tt), free(fits), free(labels);
    for (size_t i = 0; i < nb; i++)
        pp_mesh_free(&bones[i]);
    free(bones);
    pp_mesh_free(&skin);
    pp_tetmesh_free(&tet);
    pp_weights_free(&w);
    pp_template_free(&tmpl);
    return 0;
}

/* Bake with each backend at the same voxel size, pose both rigs the same
 * way and compare: time, tets, quality, weight bounds, and how far the
 * posed skins differ (same skin vertices, different tet meshes). */
static int compare_backends(const char *data, const char *tmpl, double mm, int threads)
{
    char skin[1024], dir[1024], rigs[2][64];
    snprintf(skin, sizeof skin, "%s/anatomy/skin.obj", data);
    snprintf(dir, sizeof dir, "%s/anatomy/bones", data);
    DIR *d = opendir(dir);
    if (!d)
        return die(dir, "cannot open");
    char **paths = calloc(256, sizeof *paths);
    size_t nb = 0;
    struct dirent *e;
    while ((e = readdir(d)) && nb < 256) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".obj"))
            continue;
        paths[nb] = malloc(strlen(dir) + len + 2);
        sprintf(paths[nb++], "%s/%s", dir, e->d_name);
    }
    closedir(d);
    const pp_tet_backend backends[2] = {PP_TET_LATTICE, PP_TET_TETGEN};
    printf("backends at voxel %.1f mm (right knee 90, right elbow 90, left hip -60; skin compared):\n", mm);
    int rc = 0;
    for (int b = 0; b < 2 && rc == 0; b++) {
        snprintf(rigs[b], sizeof rigs[b], "/tmp/bench_rig_%d_%ld.rig", b, (long)getpid());
        pp_bake_options o = {.skin_path = skin, .bone_paths = (const char *const *)paths,
                             .bone_count = nb, .template_path = tmpl, .output_path = rigs[b],
                             .resolution_mm = mm, .backend = backends[b], .threads = threads};
        pp_bake_report r;
        char err[1024];
        if (!pp_tet_backend_available(backends[b])) {
            printf("  %-8s not built in\n", pp_tet_backend_name(backends[b]));
            rc = 1;
            break;
        }
        if (pp_bake(&o, &r, err, sizeof err) < 0) {
            rc = die(pp_tet_backend_name(backends[b]), err);
        } else {
            printf("  %-8s %6.1f s (tets %5.1f s, weights %5.1f s, cor %5.1f s), %zu vertices, %zu tets, "
                   "dihedral %.1f..%.1f, weights %.3f..%.3f (%zu obtuse entries lumped), "
                   "skin outside %zu (max %.1f mm)\n",
                   pp_tet_backend_name(backends[b]), r.total_seconds,
                   r.seconds[PP_STAGE_TETRAHEDRALIZE], r.seconds[PP_STAGE_WEIGHTS],
                   r.seconds[PP_STAGE_COR], r.quality.vertex_count, r.quality.tet_count,
                   r.quality.min_dihedral_deg, r.quality.max_dihedral_deg, r.weights.min_weight,
                   r.weights.max_weight, r.weights.clipped_entries, r.tissues[0].outside,
                   r.tissues[0].max_distance * 1e3);
        }
        pp_bake_report_free(&r);
    }
    for (size_t i = 0; i < nb; i++)
        free(paths[i]);
    free(paths);
    if (rc)
        return rc;
    const pose_method methods[3] = {POSE_LBS, POSE_DQS, POSE_COR};
    for (int mth = 0; mth < 3; mth++) {
        const float *pos[2];
        pose_rig *rig[2];
        pose_state *st[2];
        size_t n = 0;
        for (int b = 0; b < 2; b++) {
            if (pose_rig_load(rigs[b], &rig[b]) != POSE_OK || pose_state_create(rig[b], &st[b]) != POSE_OK)
                return die("compare", pose_last_error());
            pose_set_method(st[b], methods[mth]);
            const float knee[3] = {0, 90, 0}, elbow[3] = {0, 90, 0}, hip[3] = {0, -60, 0};
            pose_set_joint_euler(st[b], pose_rig_find_joint(rig[b], "knee_r"), knee, POSE_EULER_XYZ);
            pose_set_joint_euler(st[b], pose_rig_find_joint(rig[b], "elbow_r"), elbow, POSE_EULER_XYZ);
            pose_set_joint_euler(st[b], pose_rig_find_joint(rig[b], "hip_l"), hip, POSE_EULER_XYZ);
            pose_apply(st[b]);
            pos[b] = pose_tissue_positions(st[b], pose_rig_find_tissue(rig[b], "skin"), &n);
        }
        /* Over the skin vertices the pose moved (> 1 mm with the lattice rig). */
        pose_tissue_info si;
        pose_rig_tissue_info(rig[0], pose_rig_find_tissue(rig[0], "skin"), &si);
        double mx = 0, sum = 0;
        size_t moved = 0;
        for (size_t v = 0; v < n; v++) {
            double d2 = 0, m2 = 0;
            for (int c = 0; c < 3; c++) {
                double a = pos[0][3 * v + c], b = pos[1][3 * v + c], r = si.rest_positions[3 * v + c];
                d2 += (a - b) * (a - b);
                m2 += (a - r) * (a - r);
            }
            if (m2 < 1e-6)
                continue;
            moved++;
            mx = fmax(mx, sqrt(d2));
            sum += sqrt(d2);
        }
        printf("  posed skin, lattice vs tetgen, %s: %zu vertices moved; difference mean %.2f mm, "
               "max %.1f mm\n", mth == 0 ? "LBS" : mth == 1 ? "DQS" : "CoR", moved,
               moved ? sum / (double)moved * 1e3 : 0.0, mx * 1e3);
        for (int b = 0; b < 2; b++) {
            pose_state_free(st[b]);
            pose_rig_free(rig[b]);
        }
    }
    remove(rigs[0]);
    remove(rigs[1]);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    const char *data = POSE_BENCH_DATA, *tmpl = POSE_BENCH_TEMPLATE;
    int threads = 2;
    size_t tissue = 0, cor_check = 0;
    int configs = 0, status = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--data") && i + 1 < argc) {
            data = argv[++i];
        } else if (!strcmp(argv[i], "--template") && i + 1 < argc) {
            tmpl = argv[++i];
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            threads = atoi(argv[++i]);
        } else if (!strcmp(argv[i], "--compare-backends") && i + 1 < argc) {
            configs++;
            status |= compare_backends(data, tmpl, atof(argv[++i]), threads);
        } else if (!strcmp(argv[i], "--cor-check") && i + 1 < argc) {
            cor_check = (size_t)atol(argv[++i]);
        } else if (!strcmp(argv[i], "--tissue-vertices") && i + 1 < argc) {
            tissue = (size_t)atol(argv[++i]);
        } else {
            double mm = atof(argv[i]);
            const char *colon = strchr(argv[i], ':');
            size_t target = colon ? (size_t)atol(colon + 1) : 0;
            if (!(mm > 0)) {
                fprintf(stderr, "usage: %s [--data DIR] [--template FILE] [--threads N] "
                                "[--tissue-vertices N] [--cor-check N] MM[:VERTICES]...\n", argv[0]);
                return 2;
            }
            configs++;
            fflush(stdout);
            pid_t pid = fork();
            if (pid == 0)
                _exit(run(data, tmpl, mm, target, threads, tissue, cor_check));
            int ws = 0;
            waitpid(pid, &ws, 0);
            if (!WIFEXITED(ws) || WEXITSTATUS(ws) != 0)
                status = 1;
        }
    }
    if (!configs) { /* the default: the shipped default resolution */
        pid_t pid = fork();
        if (pid == 0)
            _exit(run(data, tmpl, PP_BAKE_DEFAULT_RESOLUTION_MM, 0, threads, tissue, cor_check));
        int ws = 0;
        waitpid(pid, &ws, 0);
        status = !WIFEXITED(ws) || WEXITSTATUS(ws) != 0;
    }
    return status;
}
