/* mesh_import.c — Assimp scene flattening; node transforms applied on the CPU so one draw
 * per file is enough. */
#include "gfx/mesh_import.h"
#include "core/file.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define IMPORT_FLAGS (aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices \
                      | aiProcess_SortByPType | aiProcess_FindInvalidData)
#define MAX_VERTICES (64u * 1024u * 1024u)

void rt_mesh_data_free(rt_mesh_data *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

static void count_node(const struct aiScene *s, const struct aiNode *n, uint64_t *v, uint64_t *i)
{
    for (unsigned k = 0; k < n->mNumMeshes; ++k) {
        const struct aiMesh *m = s->mMeshes[n->mMeshes[k]];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        *v += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; ++f)
            if (m->mFaces[f].mNumIndices == 3)
                *i += 3;
    }
    for (unsigned c = 0; c < n->mNumChildren; ++c)
        count_node(s, n->mChildren[c], v, i);
}

static void add_node(const struct aiScene *s, const struct aiNode *n, struct aiMatrix4x4 parent,
                     rt_mesh_data *out)
{
    struct aiMatrix4x4 t = parent;
    aiMultiplyMatrix4(&t, &n->mTransformation);
    struct aiMatrix3x3 nt;
    aiMatrix3FromMatrix4(&nt, &t);
    aiMatrix3Inverse(&nt); /* normals take the inverse transpose, or non-uniform scales skew them */
    aiTransposeMatrix3(&nt);
    for (unsigned k = 0; k < n->mNumMeshes; ++k) {
        const struct aiMesh *m = s->mMeshes[n->mMeshes[k]];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        uint32_t base = out->vertex_count;
        for (unsigned v = 0; v < m->mNumVertices; ++v) {
            struct aiVector3D p = m->mVertices[v];
            aiTransformVecByMatrix4(&p, &t);
            struct aiVector3D q = m->mNormals ? m->mNormals[v] : (struct aiVector3D){0, 1, 0};
            aiTransformVecByMatrix3(&q, &nt);
            float len = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
            if (!(len > 0))
                len = 1, q = (struct aiVector3D){0, 1, 0};
            float *pp = &out->positions[3 * (size_t)out->vertex_count];
            float *nn = &out->normals[3 * (size_t)out->vertex_count];
            pp[0] = p.x, pp[1] = p.y, pp[2] = p.z;
            nn[0] = q.x / len, nn[1] = q.y / len, nn[2] = q.z / len;
            for (int a = 0; a < 3; ++a) {
                if (pp[a] < out->bounds_min[a]) out->bounds_min[a] = pp[a];
                if (pp[a] > out->bounds_max[a]) out->bounds_max[a] = pp[a];
            }
            out->vertex_count++;
        }
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            const struct aiFace *face = &m->mFaces[f];
            if (face->mNumIndices != 3)
                continue;
            for (int a = 0; a < 3; ++a)
                out->indices[out->index_count++] = base + face->mIndices[a];
        }
    }
    for (unsigned c = 0; c < n->mNumChildren; ++c)
        add_node(s, n->mChildren[c], t, out);
}

static vfx_result from_scene(const struct aiScene *s, const char *what, rt_mesh_data *out,
                             char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (!s) {
        snprintf(err, errlen, "%s: assimp: %s", what, aiGetErrorString());
        return VFX_ERR_FORMAT;
    }
    if (!s->mRootNode || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        snprintf(err, errlen, "%s: assimp: incomplete scene", what);
        aiReleaseImport(s);
        return VFX_ERR_FORMAT;
    }
    uint64_t nv = 0, ni = 0;
    count_node(s, s->mRootNode, &nv, &ni);
    if (nv == 0 || ni == 0) {
        snprintf(err, errlen, "%s: no triangles in the file", what);
        aiReleaseImport(s);
        return VFX_ERR_FORMAT;
    }
    if (nv > MAX_VERTICES || ni > 3ull * MAX_VERTICES) {
        snprintf(err, errlen, "%s: %llu vertices exceed the limit of %u", what,
                 (unsigned long long)nv, MAX_VERTICES);
        aiReleaseImport(s);
        return VFX_ERR_FORMAT;
    }
    out->positions = malloc(nv * 3 * sizeof(float));
    out->normals = malloc(nv * 3 * sizeof(float));
    out->indices = malloc(ni * sizeof(uint32_t));
    if (!out->positions || !out->normals || !out->indices) {
        rt_mesh_data_free(out);
        aiReleaseImport(s);
        snprintf(err, errlen, "%s: out of memory", what);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (int a = 0; a < 3; ++a)
        out->bounds_min[a] = INFINITY, out->bounds_max[a] = -INFINITY;
    struct aiMatrix4x4 id;
    aiIdentityMatrix4(&id);
    add_node(s, s->mRootNode, id, out);
    aiReleaseImport(s);
    for (uint32_t i = 0; i < out->vertex_count * 3; ++i)
        if (!isfinite(out->positions[i])) {
            snprintf(err, errlen, "%s: vertex %u has a non-finite coordinate", what, i / 3);
            rt_mesh_data_free(out);
            return VFX_ERR_FORMAT;
        }
    return VFX_OK;
}

vfx_result rt_mesh_import(const char *path, rt_mesh_data *out, char *err, size_t errlen)
{
    if (!path || !out)
        return VFX_ERR_INVALID_ARGUMENT;
    /* checked before Assimp opens it: a FIFO would block, a directory or device is no mesh */
    vfx_result r = rt_check_regular_file(path, err, errlen);
    if (r) {
        memset(out, 0, sizeof *out);
        return r;
    }
    return from_scene(aiImportFile(path, IMPORT_FLAGS), path, out, err, errlen);
}

vfx_result rt_mesh_import_memory(const void *data, size_t size, const char *hint,
                                  rt_mesh_data *out, char *err, size_t errlen)
{
    if (!data || !out || size == 0 || size > UINT32_MAX)
        return VFX_ERR_INVALID_ARGUMENT;
    return from_scene(aiImportFileFromMemory(data, (unsigned)size, IMPORT_FLAGS, hint), "(memory)",
                      out, err, errlen);
}

vfx_result rt_mesh_make_box(const float mn[3], const float mx[3], rt_mesh_data *out)
{
    memset(out, 0, sizeof *out);
    out->positions = malloc(24 * 3 * sizeof(float));
    out->normals = malloc(24 * 3 * sizeof(float));
    out->indices = malloc(36 * sizeof(uint32_t));
    if (!out->positions || !out->normals || !out->indices) {
        rt_mesh_data_free(out);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (int face = 0; face < 6; ++face) {
        int axis = face / 2, sign = face % 2 ? 1 : -1;
        int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int k = 0; k < 4; ++k) {
            float p[3];
            p[axis] = sign > 0 ? mx[axis] : mn[axis];
            int cu = (k == 1 || k == 2), cv = (k >= 2);
            if (sign < 0) cu = !cu; /* keep counter-clockwise seen from outside */
            p[u] = cu ? mx[u] : mn[u];
            p[v] = cv ? mx[v] : mn[v];
            uint32_t vi = out->vertex_count++;
            memcpy(&out->positions[3 * vi], p, sizeof p);
            float n[3] = {0, 0, 0};
            n[axis] = (float)sign;
            memcpy(&out->normals[3 * vi], n, sizeof n);
        }
        uint32_t b = (uint32_t)face * 4;
        uint32_t idx[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(&out->indices[out->index_count], idx, sizeof idx);
        out->index_count += 6;
    }
    memcpy(out->bounds_min, mn, 3 * sizeof(float));
    memcpy(out->bounds_max, mx, 3 * sizeof(float));
    return VFX_OK;
}

vfx_result rt_mesh_upload(const rt_mesh_data *m, rt_mesh_gpu *out)
{
    memset(out, 0, sizeof *out);
    if (!m || !m->vertex_count || !m->index_count)
        return VFX_ERR_INVALID_ARGUMENT;
    size_t vbytes = (size_t)m->vertex_count * 3 * sizeof(float);
    glCreateBuffers(1, &out->vbo);
    glNamedBufferStorage(out->vbo, (GLsizeiptr)(2 * vbytes), NULL, GL_DYNAMIC_STORAGE_BIT);
    glNamedBufferSubData(out->vbo, 0, (GLsizeiptr)vbytes, m->positions);
    glNamedBufferSubData(out->vbo, (GLintptr)vbytes, (GLsizeiptr)vbytes, m->normals);
    glCreateBuffers(1, &out->ibo);
    glNamedBufferStorage(out->ibo, (GLsizeiptr)(m->index_count * sizeof(uint32_t)), m->indices, 0);
    glCreateVertexArrays(1, &out->vao);
    glVertexArrayVertexBuffer(out->vao, 0, out->vbo, 0, 3 * sizeof(float));
    glVertexArrayVertexBuffer(out->vao, 1, out->vbo, (GLintptr)vbytes, 3 * sizeof(float));
    glVertexArrayElementBuffer(out->vao, out->ibo);
    for (GLuint a = 0; a < 2; ++a) {
        glEnableVertexArrayAttrib(out->vao, a);
        glVertexArrayAttribFormat(out->vao, a, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(out->vao, a, a);
    }
    glObjectLabel(GL_VERTEX_ARRAY, out->vao, -1, "host.mesh");
    out->index_count = m->index_count;
    return glGetError() == GL_NO_ERROR ? VFX_OK : VFX_ERR_GL;
}

void rt_mesh_gpu_destroy(rt_mesh_gpu *g)
{
    if (!g)
        return;
    glDeleteVertexArrays(1, &g->vao);
    glDeleteBuffers(1, &g->vbo);
    glDeleteBuffers(1, &g->ibo);
    memset(g, 0, sizeof *g);
}
