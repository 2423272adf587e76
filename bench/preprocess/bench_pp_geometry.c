/* SPDX-License-Identifier: Apache-2.0
 *
 * Geometry stages of pose-bake on the shared body: load, voxelize + label,
 * tetrahedralize with each backend; prints time, counts, quality and peak
 * memory. Every bone gets its own label (the worst case for labelling).
 *
 *   bench_pp_geometry [--data DIR] [--spacing M] [--target N]
 *                     [--backend lattice|tetgen|all] [--json]
 *
 * "lattice" runs the built-in mesher twice: uniform Kuhn lattice and graded
 * octree (the default). Wall and CPU seconds are both printed: the machine
 * may be shared.
 */
#include "mesh_io.h"
#include "tetmesh.h"
#include "voxelize.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double peak_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void usage(void)
{
    fprintf(stderr, "usage: bench_pp_geometry [--data DIR] [--spacing M] [--target N] "
                    "[--backend lattice|tetgen|all] [--json]\n");
}

int main(int argc, char **argv)
{
    const char *data = getenv("POSE_DATA_DIR") ? getenv("POSE_DATA_DIR") : POSE_DATA_DIR_DEFAULT;
    float spacing = 0.005f;
    size_t target = 0;
    const char *backend = "all";
    int json = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--data") && i + 1 < argc)
            data = argv[++i];
        else if (!strcmp(argv[i], "--spacing") && i + 1 < argc)
            spacing = strtof(argv[++i], NULL);
        else if (!strcmp(argv[i], "--target") && i + 1 < argc)
            target = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "--backend") && i + 1 < argc)
            backend = argv[++i];
        else if (!strcmp(argv[i], "--json"))
            json = 1;
        else {
            usage();
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    char err[512], path[1024];
    double t0 = now_s();
    pp_mesh skin;
    snprintf(path, sizeof path, "%s/anatomy/skin.obj", data);
    if (pp_mesh_load(path, &skin, err, sizeof err) != POSE_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    snprintf(path, sizeof path, "%s/anatomy/bones", data);
    DIR *d = opendir(path);
    if (!d) {
        fprintf(stderr, "%s: cannot open\n", path);
        return 1;
    }
    char *names[256];
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)) && n < 256)
        if (strstr(e->d_name, ".obj"))
            names[n++] = strdup(e->d_name);
    closedir(d);
    qsort(names, n, sizeof *names, cmp_str);
    pp_mesh *bones = calloc(n, sizeof *bones);
    uint16_t *lab = calloc(n, sizeof *lab);
    size_t bone_tris = 0;
    for (size_t i = 0; i < n; i++) {
        snprintf(path, sizeof path, "%s/anatomy/bones/%s", data, names[i]);
        if (pp_mesh_load(path, &bones[i], err, sizeof err) != POSE_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        lab[i] = (uint16_t)i;
        bone_tris += bones[i].triangle_count;
        free(names[i]);
    }
    double t_load = now_s() - t0;

    pp_voxels v;
    pp_voxel_report r;
    if (pp_voxelize(&skin, bones, lab, n, spacing, &v, &r, err, sizeof err) != POSE_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    if (json)
        printf("{\"spacing\": %g, \"load_s\": %.3f, \"bones\": %zu, \"bone_triangles\": %zu,\n"
               " \"voxelize\": {\"s\": %.3f, \"grid\": [%d, %d, %d], \"body_m3\": %.5f, "
               "\"skin_m3\": %.5f, \"bone_voxels\": %zu, \"outside_skin\": %zu, \"overlap\": %zu, "
               "\"ambiguous\": %zu, \"thin_bones\": %zu, \"open_bones\": %zu},\n \"backends\": [",
               (double)spacing, t_load, n, bone_tris, r.seconds, v.nx, v.ny, v.nz, r.body_volume,
               r.skin_volume, r.bone_voxels, r.bone_voxels_outside_skin, r.overlap_voxels,
               r.ambiguous_voxels, r.thin_bones, r.open_bone_meshes);
    else
        printf("shared body: skin %zu tris, %zu bones %zu tris, load %.3f s\n"
               "voxelize @ %.1f mm: %.3f s, grid %dx%dx%d, body %.5f m^3 (skin alone %.5f), "
               "bone voxels %zu, promoted %zu, overlaps %zu, ties %zu, thin bones %zu, "
               "open bones %zu\n",
               skin.triangle_count, n, bone_tris, t_load, 1000.0 * spacing, r.seconds, v.nx, v.ny,
               v.nz, r.body_volume, r.skin_volume, r.bone_voxels, r.bone_voxels_outside_skin,
               r.overlap_voxels, r.ambiguous_voxels, r.thin_bones, r.open_bone_meshes);
    int first = 1;
    static const struct {
        const char *name;
        pp_tet_backend backend;
        int grading;
    } variants[] = {{"uniform", PP_TET_LATTICE, -1},
                    {"graded", PP_TET_LATTICE, 0},
                    {"tetgen", PP_TET_TETGEN, 0}};
    for (size_t vi = 0; vi < sizeof variants / sizeof variants[0]; vi++) {
        pp_tet_backend b = variants[vi].backend;
        if (strcmp(backend, "all") && strcmp(backend, pp_tet_backend_name(b)))
            continue;
        if (!pp_tet_backend_available(b))
            continue;
        pp_tet_options o = {.backend = b, .target_vertices = target, .grading = variants[vi].grading};
        pp_tetmesh t;
        pp_tet_quality q;
        double c0 = cpu_s();
        if (pp_tetrahedralize(&v, &skin, &o, &t, &q, err, sizeof err) != POSE_OK) {
            fprintf(stderr, "%s: %s\n", variants[vi].name, err);
            continue;
        }
        double cpu = cpu_s() - c0; /* includes the quality measurement */
        size_t bone_tets = 0;
        for (size_t i = 0; i < t.tet_count; i++)
            bone_tets += t.labels[i] != 0;
        if (json)
            printf("%s\n  {\"variant\": \"%s\", \"backend\": \"%s\", \"s\": %.3f, \"cpu_s\": %.3f, "
                   "\"vertices\": %zu, \"tets\": %zu, \"bone_tets\": %zu, \"volume_m3\": %.5f, "
                   "\"min_dihedral_deg\": %.2f, \"max_dihedral_deg\": %.2f, "
                   "\"max_radius_edge\": %.3f, \"min_volume_m3\": %.3g, \"inverted\": %zu, "
                   "\"labels_lost\": %zu}",
                   first ? "" : ",", variants[vi].name, pp_tet_backend_name(b), q.seconds, cpu,
                   q.vertex_count, q.tet_count, bone_tets, q.total_volume, q.min_dihedral_deg,
                   q.max_dihedral_deg, q.max_radius_edge, q.min_volume, q.inverted_count,
                   q.labels_lost);
        else
            printf("%-8s %7.3f s (cpu %.3f)  %8zu vertices %9zu tets (%zu bone)  volume %.5f m^3  "
                   "dihedral %.1f..%.1f deg  radius-edge <= %.2f  min vol %.3g m^3  inverted %zu  "
                   "labels lost %zu\n",
                   variants[vi].name, q.seconds, cpu, q.vertex_count, q.tet_count, bone_tets,
                   q.total_volume, q.min_dihedral_deg, q.max_dihedral_deg, q.max_radius_edge,
                   q.min_volume, q.inverted_count, q.labels_lost);
        first = 0;
        pp_tetmesh_free(&t);
    }
    if (json)
        printf("\n ],\n \"peak_rss_mib\": %.1f}\n", peak_mib());
    else
        printf("peak RSS %.1f MiB\n", peak_mib());
    pp_voxels_free(&v);
    for (size_t i = 0; i < n; i++)
        pp_mesh_free(&bones[i]);
    free(bones);
    free(lab);
    pp_mesh_free(&skin);
    return 0;
}
