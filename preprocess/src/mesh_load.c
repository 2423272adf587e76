/* SPDX-License-Identifier: Apache-2.0
 *
 * pp_mesh_load: any Assimp format -> one welded triangle mesh. Assimp does the
 * parsing (it is the well-kept reader for dozens of formats); here we only
 * walk the node tree, apply node transforms, weld on exact position equality
 * (Assimp's own JoinIdenticalVertices also compares normals and UVs, so UV
 * seams would stay split) and drop degenerate triangles.
 */
#include "mesh_io.h"
#include "mesh_weld.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void set_err(char *err, size_t errlen, const char *fmt, const char *path, const char *what)
{
    if (err && errlen)
        snprintf(err, errlen, fmt, path, what);
}

/* Count the triangles and vertices reachable through the node tree (a mesh
 * referenced by two nodes is instanced twice). */
static void count_node(const struct aiScene *sc, const struct aiNode *node, size_t *nv, size_t *nt)
{
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[node->mMeshes[i]];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        *nv += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; f++)
            if (m->mFaces[f].mNumIndices == 3)
                (*nt)++;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        count_node(sc, node->mChildren[c], nv, nt);
}

static void gather_node(const struct aiScene *sc, const struct aiNode *node,
                        struct aiMatrix4x4 parent, pp_mesh *out)
{
    struct aiMatrix4x4 world = parent;
    aiMultiplyMatrix4(&world, &node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[node->mMeshes[i]];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        uint32_t base = (uint32_t)out->vertex_count;
        for (unsigned v = 0; v < m->mNumVertices; v++) {
            struct aiVector3D p = m->mVertices[v];
            aiTransformVecByMatrix4(&p, &world);
            float *dst = out->positions + 3 * out->vertex_count++;
            dst[0] = (float)p.x;
            dst[1] = (float)p.y;
            dst[2] = (float)p.z;
        }
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            const struct aiFace *face = &m->mFaces[f];
            if (face->mNumIndices != 3)
                continue;
            uint32_t *dst = out->triangles + 3 * out->triangle_count++;
            for (int k = 0; k < 3; k++)
                dst[k] = base + face->mIndices[k];
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; c++)
        gather_node(sc, node->mChildren[c], world, out);
}

static void base_name(const char *path, char *name, size_t cap)
{
    const char *s = strrchr(path, '/');
    s = s ? s + 1 : path;
    size_t n = strlen(s);
    const char *dot = strrchr(s, '.');
    if (dot && dot != s)
        n = (size_t)(dot - s);
    if (n >= cap)
        n = cap - 1;
    memcpy(name, s, n);
    name[n] = '\0';
}

pose_status pp_mesh_load(const char *path, pp_mesh *out, char *err, size_t errlen)
{
    if (!out)
        return POSE_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!path || !*path) {
        set_err(err, errlen, "%s%s", "(no path)", ": empty mesh file name");
        return POSE_ERR_INVALID_ARGUMENT;
    }
    /* Assimp's "unable to open" text does not say why; stat does. */
    struct stat st;
    if (stat(path, &st) != 0) {
        set_err(err, errlen, "%s: %s", path, strerror(errno));
        return POSE_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        set_err(err, errlen, "%s: %s", path, "not a regular file");
        return POSE_ERR_IO;
    }
    if (st.st_size == 0) {
        set_err(err, errlen, "%s: %s", path, "empty file");
        return POSE_ERR_FORMAT;
    }

    const struct aiScene *sc = aiImportFile(path, aiProcess_Triangulate | aiProcess_SortByPType);
    if (!sc || !sc->mRootNode) {
        const char *why = aiGetErrorString();
        set_err(err, errlen, "%s: cannot read mesh: %s", path, why && *why ? why : "unknown format");
        if (sc)
            aiReleaseImport(sc);
        return POSE_ERR_FORMAT;
    }
    size_t nv = 0, nt = 0;
    count_node(sc, sc->mRootNode, &nv, &nt);
    if (nt == 0) {
        aiReleaseImport(sc);
        set_err(err, errlen, "%s: %s", path, "no triangles");
        return POSE_ERR_FORMAT;
    }
    if (nv > UINT32_MAX || nt > UINT32_MAX / 3) {
        aiReleaseImport(sc);
        set_err(err, errlen, "%s: %s", path, "too many vertices for 32-bit indices");
        return POSE_ERR_FORMAT;
    }
    out->positions = malloc(3 * nv * sizeof *out->positions);
    out->triangles = malloc(3 * nt * sizeof *out->triangles);
    if (!out->positions || !out->triangles) {
        aiReleaseImport(sc);
        pp_mesh_free(out);
        set_err(err, errlen, "%s: %s", path, "out of memory");
        return POSE_ERR_OUT_OF_MEMORY;
    }
    struct aiMatrix4x4 id;
    aiIdentityMatrix4(&id);
    gather_node(sc, sc->mRootNode, id, out);
    aiReleaseImport(sc);
    base_name(path, out->name, sizeof out->name);

    for (size_t i = 0; i < 3 * out->vertex_count; i++) {
        if (!isfinite(out->positions[i])) {
            char what[96];
            snprintf(what, sizeof what, "vertex %zu has a non-finite coordinate", i / 3 + 1);
            set_err(err, errlen, "%s: %s", path, what);
            pp_mesh_free(out);
            return POSE_ERR_FORMAT;
        }
    }
    pose_status s = pp_mesh_weld(out);
    if (s != POSE_OK) {
        set_err(err, errlen, "%s: %s", path, "out of memory");
        pp_mesh_free(out);
        return s;
    }
    if (out->triangle_count == 0) {
        set_err(err, errlen, "%s: %s", path, "all triangles are degenerate");
        pp_mesh_free(out);
        return POSE_ERR_FORMAT;
    }
    return POSE_OK;
}
