/* mesh_import.c — Assimp scene flattening; node transforms applied on the CPU so one draw
 * per file is enough. Assimp runs only in a child process (core/sandbox.h) with limits on its
 * CPU time, memory and stack: a crash, hang or blow-up inside it is an error naming the file,
 * and the host reads back only the flattened arrays, checked (counts under the caps, indices in
 * range, every value finite). In the child, Assimp never sees a file the checks of mesh_check.c
 * have not passed, and every file it opens goes through import_io below, so an .mtl or .bin it
 * follows is held to the same rules (regular file, size cap) as the mesh. */
#define _POSIX_C_SOURCE 200809L
#include "gfx/mesh_import.h"
#include "core/file.h"
#include "core/sandbox.h"
#include "gfx/mesh_check.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <epoxy/gl.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ValidateDataStructure first: Assimp's later steps index vertices with the file's face
 * indices unchecked (a truncated binary PLY crashed in JoinIdenticalVertices). */
#define IMPORT_FLAGS (aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_GenSmoothNormals \
                      | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType | aiProcess_FindInvalidData)
#define MAX_VERTICES RT_MESH_MAX_PLACED_VERTICES
#define MAX_INDICES (3ull * MAX_VERTICES)
#define MAX_NODE_DEPTH RT_MESH_MAX_NODE_DEPTH
#define MAX_EXTERNAL 8

void rt_mesh_data_free(rt_mesh_data *m)
{
    if (!m)
        return;
    free(m->positions);
    free(m->normals);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

/* ---- the files Assimp may open --------------------------------------------------------------- */

typedef struct import_io {
    struct aiFileIO io;
    const char *main_name; /* served from `main`, read and checked before Assimp started */
    const unsigned char *main;
    size_t main_size;
    int allow_external; /* file imports: files beside it (an .mtl, a .bin); memory imports: none */
    char *ext_name[MAX_EXTERNAL];
    char *ext_data[MAX_EXTERNAL];
    size_t ext_size[MAX_EXTERNAL];
    unsigned ext_count;
    size_t total; /* bytes of every file this import holds */
    vfx_result refused;
    char refusal[512];
} import_io;

typedef struct open_file {
    struct aiFile f;
    const unsigned char *data;
    size_t size, pos;
} open_file;

static size_t of_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    open_file *o = (open_file *)f->UserData;
    if (size == 0 || count == 0)
        return 0;
    size_t items = (o->size - o->pos) / size;
    if (items > count)
        items = count;
    memcpy(buf, o->data + o->pos, items * size);
    o->pos += items * size;
    return items;
}

static size_t of_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0; /* importing writes nothing */
}

static size_t of_tell(struct aiFile *f) { return ((open_file *)f->UserData)->pos; }
static size_t of_size(struct aiFile *f) { return ((open_file *)f->UserData)->size; }
static void of_flush(struct aiFile *f) { (void)f; }

static enum aiReturn of_seek(struct aiFile *f, size_t off, enum aiOrigin origin)
{
    open_file *o = (open_file *)f->UserData;
    /* Assimp passes a negative offset as its size_t: the unsigned sum wraps to the target */
    size_t to = origin == aiOrigin_SET ? off : origin == aiOrigin_CUR ? o->pos + off : o->size + off;
    if (to > o->size)
        return aiReturn_FAILURE;
    o->pos = to;
    return aiReturn_SUCCESS;
}

static void io_refuse(import_io *x, vfx_result r, const char *name, const char *why)
{
    if (x->refused)
        return;
    x->refused = r;
    snprintf(x->refusal, sizeof x->refusal, "%s: references %s, refused: %s", x->main_name, name, why);
}

/* An external file: read whole through rt_read_file (regular files only, within what is left
 * of the import's byte cap), kept until the import ends. A missing file is NULL as Assimp
 * expects (an OBJ without its .mtl still imports); one refused fails the import. */
static int io_external(import_io *x, const char *name, const unsigned char **data, size_t *size)
{
    for (unsigned i = 0; i < x->ext_count; ++i)
        if (strcmp(x->ext_name[i], name) == 0) {
            *data = (const unsigned char *)x->ext_data[i], *size = x->ext_size[i];
            return 1;
        }
    if (!x->allow_external)
        return 0;
    struct stat st;
    if (stat(name, &st) != 0 && errno == ENOENT)
        return 0;
    if (x->ext_count == MAX_EXTERNAL) {
        io_refuse(x, VFX_ERR_FORMAT, name, "more than 8 other files for one mesh");
        return 0;
    }
    char msg[400], cap[64], *buf = NULL;
    size_t n = 0, left = RT_MESH_MAX_BYTES - x->total;
    snprintf(cap, sizeof cap, "%zu bytes (what is left of %s for the mesh and its files)", left,
             RT_MESH_MAX_BYTES_TEXT);
    vfx_result r = rt_read_file(name, left, cap, &buf, &n, msg, sizeof msg);
    if (r) {
        io_refuse(x, r, name, msg);
        return 0;
    }
    x->ext_name[x->ext_count] = strdup(name);
    if (!x->ext_name[x->ext_count]) {
        free(buf);
        io_refuse(x, VFX_ERR_OUT_OF_MEMORY, name, "out of memory");
        return 0;
    }
    x->ext_data[x->ext_count] = buf;
    x->ext_size[x->ext_count++] = n;
    x->total += n;
    *data = (const unsigned char *)buf, *size = n;
    return 1;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *name, const char *mode)
{
    import_io *x = (import_io *)io->UserData;
    if (!name || strpbrk(mode ? mode : "", "wa+"))
        return NULL;
    const unsigned char *data;
    size_t size;
    if (strcmp(name, x->main_name) == 0)
        data = x->main, size = x->main_size;
    else if (!io_external(x, name, &data, &size))
        return NULL;
    open_file *o = calloc(1, sizeof *o);
    if (!o)
        return NULL;
    o->f = (struct aiFile){.ReadProc = of_read, .WriteProc = of_write, .TellProc = of_tell,
                           .FileSizeProc = of_size, .SeekProc = of_seek, .FlushProc = of_flush,
                           .UserData = (aiUserData)o};
    o->data = data, o->size = size;
    return &o->f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    free(f ? f->UserData : NULL);
}

static void io_release(import_io *x)
{
    for (unsigned i = 0; i < x->ext_count; ++i)
        free(x->ext_name[i]), free(x->ext_data[i]);
    x->ext_count = 0;
}

/* ---- flattening ------------------------------------------------------------------------------ */

static int count_node(const struct aiScene *s, const struct aiNode *n, unsigned depth, uint64_t *v,
                      uint64_t *i)
{
    if (depth > MAX_NODE_DEPTH)
        return 0;
    for (unsigned k = 0; k < n->mNumMeshes; ++k) {
        const struct aiMesh *m = s->mMeshes[n->mMeshes[k]];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        *v += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; ++f)
            if (m->mFaces[f].mNumIndices == 3)
                *i += 3;
    }
    for (unsigned c = 0; c < n->mNumChildren && *v <= MAX_VERTICES; ++c) /* over the cap: counted enough */
        if (!count_node(s, n->mChildren[c], depth + 1, v, i))
            return 0;
    return 1;
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
            for (int a = 0; a < 3; ++a) /* ValidateDataStructure proved each < mNumVertices */
                out->indices[out->index_count++] = base + face->mIndices[a];
        }
    }
    for (unsigned c = 0; c < n->mNumChildren; ++c)
        add_node(s, n->mChildren[c], t, out);
}

static vfx_result from_scene(const struct aiScene *s, const char *what, rt_mesh_data *out,
                             char *err, size_t errlen)
{
    if (!s->mRootNode || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
        snprintf(err, errlen, "%s: assimp: incomplete scene", what);
        return VFX_ERR_FORMAT;
    }
    uint64_t nv = 0, ni = 0;
    if (!count_node(s, s->mRootNode, 0, &nv, &ni)) {
        snprintf(err, errlen, "%s: node hierarchy deeper than %u", what, MAX_NODE_DEPTH);
        return VFX_ERR_FORMAT;
    }
    if (nv == 0 || ni == 0) {
        snprintf(err, errlen, "%s: no triangles in the file", what);
        return VFX_ERR_FORMAT;
    }
    if (nv > MAX_VERTICES || ni > MAX_INDICES) {
        snprintf(err, errlen, "%s: %s%llu vertices once every node's meshes are placed, above the cap of %u",
                 what, nv > MAX_VERTICES ? "over " : "", (unsigned long long)nv, MAX_VERTICES);
        return VFX_ERR_FORMAT;
    }
    out->positions = malloc(nv * 3 * sizeof(float));
    out->normals = malloc(nv * 3 * sizeof(float));
    out->indices = malloc(ni * sizeof(uint32_t));
    if (!out->positions || !out->normals || !out->indices) {
        rt_mesh_data_free(out);
        snprintf(err, errlen, "%s: out of memory", what);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (int a = 0; a < 3; ++a)
        out->bounds_min[a] = INFINITY, out->bounds_max[a] = -INFINITY;
    struct aiMatrix4x4 id;
    aiIdentityMatrix4(&id);
    add_node(s, s->mRootNode, id, out);
    for (uint32_t i = 0; i < out->vertex_count * 3; ++i)
        if (!isfinite(out->positions[i])) {
            snprintf(err, errlen, "%s: vertex %u has a non-finite coordinate", what, i / 3);
            rt_mesh_data_free(out);
            return VFX_ERR_FORMAT;
        }
    return VFX_OK;
}

/* 1 + the first mesh whose primitive-type flags are not exactly the kinds of its faces, or 0.
 * Assimp 5.2's Triangulate step asserts (abort(), asserts are on in Debian's build) when a
 * mesh says POLYGON but holds none; ValidateDataStructure checks only that no kind is missing,
 * and lets a face of no index through. A fuzzed PLY (a face list of count 0) reached it. */
static unsigned primitive_types_disagree(const struct aiScene *s)
{
    for (unsigned m = 0; m < s->mNumMeshes; ++m) {
        const struct aiMesh *mesh = s->mMeshes[m];
        unsigned kinds = 0;
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            unsigned n = mesh->mFaces[f].mNumIndices;
            if (n == 0) /* counted as a polygon by Triangulate, so it asserts too */
                return m + 1;
            kinds |= n == 1 ? aiPrimitiveType_POINT : n == 2 ? aiPrimitiveType_LINE
                     : n == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
        }
        if ((mesh->mPrimitiveTypes & (aiPrimitiveType_POINT | aiPrimitiveType_LINE | aiPrimitiveType_TRIANGLE
                                      | aiPrimitiveType_POLYGON)) != kinds)
            return m + 1;
    }
    return 0;
}

/* The first vertex position that is NaN or infinite, described in msg; false when none. */
static bool non_finite_vertex(const struct aiScene *s, char *msg, size_t len)
{
    for (unsigned m = 0; m < s->mNumMeshes; ++m) {
        const struct aiMesh *mesh = s->mMeshes[m];
        for (unsigned v = 0; mesh->mVertices && v < mesh->mNumVertices; ++v) {
            const float c[3] = {mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z};
            for (int k = 0; k < 3; ++k)
                if (!isfinite(c[k])) {
                    snprintf(msg, len, "mesh %u vertex %u has a non-finite %c (%g): a mesh with such a vertex "
                             "cannot be drawn", m, v, "xyz"[k], (double)c[k]);
                    return true;
                }
        }
    }
    return false;
}

/* Checks the bytes, has Assimp read them (validated, nothing else) and counts the vertices;
 * only a scene under the cap is read again with the post-processing, the costly part (~700
 * bytes a vertex). Two reads, because Assimp 5.2's aiApplyPostProcessing frees the scene when
 * a step fails and then releases it again (SIGSEGV on BoxWithInfinites.glb): the one-call
 * import handles that failure correctly. The raw read costs about a sixth of the full one. */
static vfx_result import_checked(import_io *x, rt_mesh_format fmt, unsigned flags, rt_mesh_data *out, char *err,
                                 size_t errlen)
{
    const char *name = x->main_name;
    vfx_result r = flags & RT_MESH_IMPORT_UNCHECKED ? VFX_OK
                   : rt_mesh_check_bytes(fmt, x->main, x->main_size, name, err, errlen);
    if (r)
        return r;
    x->io = (struct aiFileIO){.OpenProc = io_open, .CloseProc = io_close, .UserData = (aiUserData)x};
    const struct aiScene *s = NULL;
    for (int pass = 0; pass < 2 && !r; ++pass) {
        s = aiImportFileEx(name, pass ? IMPORT_FLAGS : aiProcess_ValidateDataStructure, &x->io);
        if (x->refused) {
            snprintf(err, errlen, "%s", x->refusal);
            r = x->refused;
        } else if (!s) {
            snprintf(err, errlen, "%s: assimp: %s", name, aiGetErrorString());
            r = VFX_ERR_FORMAT;
        } else if (pass == 0) {
            uint64_t nv = 0;
            for (unsigned m = 0; m < s->mNumMeshes; ++m)
                nv += s->mMeshes[m]->mNumVertices;
            unsigned bad = primitive_types_disagree(s);
            char nf[160];
            if (non_finite_vertex(s, nf, sizeof nf)) {
                /* FindInvalidData would drop the mesh: "No meshes remaining", or one mesh gone */
                snprintf(err, errlen, "%s: %s", name, nf);
                r = VFX_ERR_FORMAT;
            } else if (bad) {
                snprintf(err, errlen, "%s: mesh %u: a face of no index, or faces that disagree with the "
                         "primitive types the reader gave them (Assimp's triangulation would abort)", name, bad - 1);
                r = VFX_ERR_FORMAT;
            } else if (nv > RT_MESH_MAX_IMPORT_VERTICES) {
                snprintf(err, errlen, "%s: %llu vertices, above the cap of %u", name, (unsigned long long)nv,
                         RT_MESH_MAX_IMPORT_VERTICES);
                r = VFX_ERR_FORMAT;
            }
            aiReleaseImport(s);
            s = NULL;
        }
    }
    if (!r)
        r = from_scene(s, name, out, err, errlen);
    if (s)
        aiReleaseImport(s);
    io_release(x);
    return r;
}

/* ---- the child process and what the host reads back ----------------------------------------- */

/* The child's answer: this header, then msg_len bytes of error text (result != 0) or the
 * arrays (positions, normals: 3 floats a vertex; indices), nothing else. */
typedef struct wire_head {
    uint32_t magic, result, msg_len, vertex_count, index_count;
} wire_head;
#define WIRE_MAGIC 0x4d584656u /* "VFXM" */
#define WIRE_MAX_MSG 1024u

typedef struct import_job {
    import_io x;
    rt_mesh_format fmt;
    unsigned flags;
    const char *name;
    rt_mesh_data *out; /* the host's */
} import_job;

static int write_all(int fd, const void *data, size_t n)
{
    const unsigned char *p = data;
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return 0;
        p += w, n -= (size_t)w;
    }
    return 1;
}

/* In the child: checks, Assimp, flattening; the answer to the host. */
static vfx_result import_child(void *arg, int fd)
{
    import_job *job = arg;
    rt_mesh_data m = {0};
    char err[WIRE_MAX_MSG] = "";
    vfx_result r = import_checked(&job->x, job->fmt, job->flags, &m, err, sizeof err);
    wire_head h = {WIRE_MAGIC, (uint32_t)r, 0, m.vertex_count, m.index_count};
    int ok;
    if (r) {
        h.msg_len = (uint32_t)strnlen(err, sizeof err - 1);
        ok = write_all(fd, &h, sizeof h) && write_all(fd, err, h.msg_len);
    } else {
        size_t vb = (size_t)m.vertex_count * 3 * sizeof(float);
        ok = write_all(fd, &h, sizeof h) && write_all(fd, m.positions, vb) && write_all(fd, m.normals, vb)
             && write_all(fd, m.indices, (size_t)m.index_count * sizeof(uint32_t));
    }
    rt_mesh_data_free(&m);
    return ok ? r : VFX_ERR_IO;
}

/* In the host: the answer, trusted in nothing: counts under the caps, every index in range,
 * every value finite; the bounds computed here. */
static vfx_result import_reader(void *arg, rt_sandbox_stream *st, char *err, size_t errlen)
{
    import_job *job = arg;
    rt_mesh_data *out = job->out;
    wire_head h;
    if (rt_sandbox_read(st, &h, sizeof h))
        return VFX_ERR_FORMAT; /* the sandbox says what happened to the child */
    if (h.magic != WIRE_MAGIC || (h.result && (h.msg_len == 0 || h.msg_len >= WIRE_MAX_MSG))) {
        snprintf(err, errlen, "%s: the process that reads it answered garbage", job->name);
        return VFX_ERR_FORMAT;
    }
    if (h.result) {
        char msg[WIRE_MAX_MSG];
        if (rt_sandbox_read(st, msg, h.msg_len))
            return VFX_ERR_FORMAT;
        msg[h.msg_len] = 0;
        snprintf(err, errlen, "%s", msg);
        return h.result <= (uint32_t)VFX_ERR_UNSUPPORTED + 16 ? (vfx_result)h.result : VFX_ERR_FORMAT;
    }
    if (h.vertex_count == 0 || h.vertex_count > MAX_VERTICES || h.index_count == 0 || h.index_count > MAX_INDICES
        || h.index_count % 3) {
        snprintf(err, errlen, "%s: the process that reads it answered %u vertices and %u indices (caps %u and %llu)",
                 job->name, h.vertex_count, h.index_count, MAX_VERTICES, MAX_INDICES);
        return VFX_ERR_FORMAT;
    }
    size_t vb = (size_t)h.vertex_count * 3 * sizeof(float);
    out->positions = malloc(vb);
    out->normals = malloc(vb);
    out->indices = malloc((size_t)h.index_count * sizeof(uint32_t));
    if (!out->positions || !out->normals || !out->indices) {
        rt_mesh_data_free(out);
        snprintf(err, errlen, "%s: out of memory for %u vertices", job->name, h.vertex_count);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    if (rt_sandbox_read(st, out->positions, vb) || rt_sandbox_read(st, out->normals, vb)
        || rt_sandbox_read(st, out->indices, (size_t)h.index_count * sizeof(uint32_t))) {
        rt_mesh_data_free(out);
        return VFX_ERR_FORMAT;
    }
    out->vertex_count = h.vertex_count, out->index_count = h.index_count;
    const char *bad = NULL;
    uint32_t at = 0;
    for (int a = 0; a < 3; ++a)
        out->bounds_min[a] = INFINITY, out->bounds_max[a] = -INFINITY;
    for (uint32_t i = 0; i < 3 * h.vertex_count && !bad; ++i) {
        float p = out->positions[i];
        if (!isfinite(p) || !isfinite(out->normals[i]))
            bad = "a non-finite position or normal", at = i / 3;
        if (p < out->bounds_min[i % 3]) out->bounds_min[i % 3] = p;
        if (p > out->bounds_max[i % 3]) out->bounds_max[i % 3] = p;
    }
    for (uint32_t i = 0; i < h.index_count && !bad; ++i)
        if (out->indices[i] >= h.vertex_count)
            bad = "an index past the vertices", at = i;
    if (bad) {
        snprintf(err, errlen, "%s: the process that reads it answered %s (at %u)", job->name, bad, at);
        rt_mesh_data_free(out);
        return VFX_ERR_FORMAT;
    }
    return VFX_OK;
}

static vfx_result import_sandboxed(import_job *job, const rt_sandbox_limits *lim, char *err, size_t errlen)
{
    rt_sandbox_limits def = rt_sandbox_default_limits();
    vfx_result r = rt_sandbox_run(lim ? lim : &def, job->name, import_child, job, import_reader, job, err, errlen);
    if (r)
        rt_mesh_data_free(job->out);
    return r;
}

vfx_result rt_mesh_import(const char *path, rt_mesh_data *out, char *err, size_t errlen)
{
    if (!path || !out)
        return VFX_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    rt_mesh_format fmt = rt_mesh_format_of_name(path);
    char *buf = NULL;
    size_t size = 0;
    /* read here, not by Assimp: a FIFO would block it, a directory or device is no mesh, and
     * the bytes checked are the bytes it parses */
    vfx_result r = rt_read_file(path, RT_MESH_MAX_BYTES, RT_MESH_MAX_BYTES_TEXT, &buf, &size, err, errlen);
    if (r)
        return r;
    if (!fmt) {
        free(buf);
        return rt_mesh_check_bytes(fmt, NULL, 0, path, err, errlen);
    }
    import_job job = {.x = {.main_name = path, .main = (const unsigned char *)buf, .main_size = size,
                            .allow_external = 1, .total = size},
                      .fmt = fmt, .name = path, .out = out};
    r = import_sandboxed(&job, NULL, err, errlen);
    free(buf);
    return r;
}

vfx_result rt_mesh_import_memory_ex(const void *data, size_t size, const char *hint, const rt_sandbox_limits *lim,
                                     unsigned flags, rt_mesh_data *out, char *err, size_t errlen)
{
    if (!data || !out || !hint || size == 0 || size > RT_MESH_MAX_BYTES) {
        if (err && errlen)
            snprintf(err, errlen, "rt_mesh_import_memory: %s (%zu bytes; NULL data, out or hint, or a size of 0 "
                     "or above %llu)", !data || !out || !hint ? "a NULL argument" : "no mesh in the bytes", size,
                     (unsigned long long)RT_MESH_MAX_BYTES);
        return VFX_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    char name[48];
    snprintf(name, sizeof name, "(memory).%.16s", hint);
    rt_mesh_format fmt = rt_mesh_format_of_name(name);
    if (!fmt)
        return rt_mesh_check_bytes(fmt, data, size, name, err, errlen);
    import_job job = {.x = {.main_name = name, .main = data, .main_size = size, .total = size},
                      .fmt = fmt, .flags = flags, .name = name, .out = out};
    return import_sandboxed(&job, lim, err, errlen);
}

vfx_result rt_mesh_import_memory(const void *data, size_t size, const char *hint,
                                  rt_mesh_data *out, char *err, size_t errlen)
{
    return rt_mesh_import_memory_ex(data, size, hint, NULL, 0, out, err, errlen);
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
