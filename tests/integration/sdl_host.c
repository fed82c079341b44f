/* sdl_host.c — volfx in a host built on SDL2, as many game runtimes are: SDL's window and GL
 * context, every GL function (the host's and the plugin's) from SDL_GL_GetProcAddress, no
 * libepoxy, nothing from runtime/. The game keeps its own particle array (a fountain stepped on
 * the CPU), two beams and a small tetrahedral volume, and draws them over its opaque pass.
 * usage: sdl_host [libvolfx.so.2] [--frames N] [--ppm FILE]
 *   runs N frames (default 8) in a 240x135 window, checks that the water, the beams and the
 *   volume each covered pixels where they should, writes the last frame as a PPM.
 * Exits 0 on success, 77 when SDL finds no display or no GL 4.5 core context. */
#include <SDL.h>
#include <SDL_opengl.h>
#include <dlfcn.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <volfx/volfx.h>

#define W 240
#define H 135
#define NP 2048

/* The host's own GL entry points, resolved through SDL like the plugin's. */
typedef struct host_gl {
    PFNGLCREATETEXTURESPROC CreateTextures;
    PFNGLTEXTURESTORAGE2DPROC TextureStorage2D;
    PFNGLCREATEFRAMEBUFFERSPROC CreateFramebuffers;
    PFNGLNAMEDFRAMEBUFFERTEXTUREPROC NamedFramebufferTexture;
    PFNGLCLEARNAMEDFRAMEBUFFERFVPROC ClearNamedFramebufferfv;
    PFNGLBLITNAMEDFRAMEBUFFERPROC BlitNamedFramebuffer;
    PFNGLGETTEXTUREIMAGEPROC GetTextureImage;
    PFNGLDELETEFRAMEBUFFERSPROC DeleteFramebuffers;
    void (APIENTRY *DeleteTextures)(GLsizei, const GLuint *);
} host_gl;

typedef struct game {
    float x[NP], y[NP], z[NP], vx[NP], vy[NP], vz[NP]; /* the game's own particle storage */
    uint64_t revision;
    vfx_beam beams[2];
    float points[8 * 3], scalar[8];
    uint32_t tets[5 * 4];
    int errors;
} game;

static void on_log(void *user, vfx_log_level level, vfx_log_id id, const char *msg)
{
    (void)id; /* the text is enough for this host */
    game *g = user;
    if (level >= VFX_LOG_WARN)
        fprintf(stderr, "volfx: %s\n", msg);
    if (level == VFX_LOG_ERROR)
        g->errors++;
}
static void *on_proc(void *user, const char *name) { (void)user; return SDL_GL_GetProcAddress(name); }
static uint32_t on_chunks(void *user) { (void)user; return 1; }
static vfx_result on_chunk(void *user, uint32_t i, vfx_particle_view *v)
{
    game *g = user;
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    v->count = NP;
    v->pos[0] = g->x, v->pos[1] = g->y, v->pos[2] = g->z;
    v->vel[0] = g->vx, v->vel[1] = g->vy, v->vel[2] = g->vz;
    v->revision = g->revision; /* bumped every step: the positions change every frame */
    return VFX_OK;
}
static vfx_result on_beams(void *user, vfx_beams_view *v)
{
    game *g = user;
    v->count = 2;
    v->beams = g->beams;
    return VFX_OK;
}
static vfx_result on_water(void *user, vfx_water_params *p)
{
    (void)user;
    p->method = VFX_WATER_METHOD_TILE; /* the recommended method; every other field default */
    return VFX_OK;
}
static uint32_t on_volumes(void *user) { (void)user; return 1; }
static vfx_result on_volume(void *user, uint32_t i, vfx_volume_view *v)
{
    game *g = user;
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    v->point_count = 8, v->tet_count = 5;
    v->points = g->points, v->tets = g->tets, v->scalar = g->scalar;
    v->revision = 1;
    return VFX_OK;
}

/* A fountain: particles shot up from (0, -1, 0), falling back into a bowl; explicit Euler with a
 * bounce on the floor y = -1.2 (the game's physics, nothing of ours). */
static void step(game *g, float dt)
{
    for (int i = 0; i < NP; ++i) {
        g->vy[i] -= 9.8f * dt;
        g->x[i] += g->vx[i] * dt, g->y[i] += g->vy[i] * dt, g->z[i] += g->vz[i] * dt;
        if (g->y[i] < -1.2f) {
            g->y[i] = -1.2f;
            g->vy[i] = -0.4f * g->vy[i];
            g->vx[i] *= 0.8f, g->vz[i] *= 0.8f;
        }
    }
    g->revision++;
}

static void setup(game *g)
{
    uint32_t r = 12345u; /* the game's own LCG */
    for (int i = 0; i < NP; ++i) {
        float u[3];
        for (int k = 0; k < 3; ++k) {
            r = r * 1664525u + 1013904223u;
            u[k] = (float)(r >> 8) / 16777216.0f;
        }
        float a = 6.2831853f * u[0], s = 0.5f * sqrtf(u[1]);
        g->x[i] = s * cosf(a), g->z[i] = s * sinf(a), g->y[i] = -1.2f + 0.6f * u[2];
        g->vx[i] = 0.6f * g->x[i], g->vz[i] = 0.6f * g->z[i], g->vy[i] = 1.5f * u[2];
    }
    g->beams[0] = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-2.2f, 1.1f, -0.5f}, .dir = {1, 0, 0}, .length = 2.5f, .radius = 0.35f,
                             .a = 0.3f, .b = 0.3f, .eps = 0.03f, .color = {1.0f, 0.5f, 0.2f, 1}};
    g->beams[1] = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {2.2f, 0.7f, -0.5f}, .dir = {-1, 0.1f, 0}, .length = 1.5f, .radius = 0.3f,
                             .a = 0.3f, .b = 0.3f, .eps = 0.03f, .color = {0.3f, 0.6f, 1.0f, 1}};
    /* a unit cube of 5 tetrahedra at the right, scalar rising with height */
    for (int i = 0; i < 8; ++i) {
        g->points[3 * i + 0] = 1.3f + 0.9f * (float)(i & 1);
        g->points[3 * i + 1] = -1.1f + 0.9f * (float)((i >> 1) & 1);
        g->points[3 * i + 2] = -0.9f + 0.9f * (float)((i >> 2) & 1);
        g->scalar[i] = (float)((i >> 1) & 1);
    }
    static const uint32_t t[20] = {0, 1, 2, 4, 1, 2, 3, 7, 1, 4, 5, 7, 2, 4, 6, 7, 1, 2, 4, 7};
    memcpy(g->tets, t, sizeof t);
}

static int load_gl(host_gl *gl)
{
#define GET(n) (*(void **)&gl->n = SDL_GL_GetProcAddress("gl" #n)) != NULL
    return GET(CreateTextures) && GET(TextureStorage2D) && GET(CreateFramebuffers) && GET(NamedFramebufferTexture)
           && GET(ClearNamedFramebufferfv) && GET(BlitNamedFramebuffer) && GET(GetTextureImage)
           && GET(DeleteFramebuffers) && GET(DeleteTextures);
#undef GET
}

/* Pixels of a read_raw image above `min` in a column range [x0, x1) (top row first). */
static int covered(const float *raw, int x0, int x1, float min)
{
    int n = 0;
    for (int y = 0; y < H; ++y)
        for (int x = x0; x < x1; ++x)
            n += raw[y * W + x] > min;
    return n;
}

int main(int argc, char **argv)
{
    const char *lib_path = NULL, *ppm = NULL;
    int frames = 8;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--ppm") && i + 1 < argc) ppm = argv[++i];
        else lib_path = argv[i];
    }
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "SDL: %s: skipping\n", SDL_GetError());
        return 77;
    }
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 4);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 5);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_Window *win = SDL_CreateWindow("volfx in SDL2", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, W, H,
                                       SDL_WINDOW_OPENGL | SDL_WINDOW_HIDDEN);
    SDL_GLContext glc = win ? SDL_GL_CreateContext(win) : NULL;
    host_gl gl;
    if (!glc || !load_gl(&gl)) {
        fprintf(stderr, "SDL: no GL 4.5 core context (%s): skipping\n", SDL_GetError());
        if (win)
            SDL_DestroyWindow(win);
        SDL_Quit();
        return 77;
    }
    const GLubyte *(APIENTRY *GetString)(GLenum) = (const GLubyte *(APIENTRY *)(GLenum))SDL_GL_GetProcAddress("glGetString");
    printf("SDL %s, video driver %s, GL %s on %s\n", SDL_GetRevision(), SDL_GetCurrentVideoDriver(),
           (const char *)GetString(GL_VERSION), (const char *)GetString(GL_RENDERER));

    static game g;
    setup(&g);
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &g,
                         .gl_get_proc_address = on_proc, .log = on_log,
                         .particle_chunk_count = on_chunks, .particle_chunk = on_chunk, .water_params = on_water,
                         .beams = on_beams, .volume_count = on_volumes, .volume = on_volume};
    vfx_plugin_entry_fn entry = vfx_plugin_entry;
    void *lib = NULL;
    if (lib_path) { /* the plugin as a game loads its plugins: dlopen, one symbol */
        lib = dlopen(lib_path, RTLD_NOW | RTLD_LOCAL);
        void *sym = lib ? dlsym(lib, VFX_ENTRY_SYMBOL) : NULL;
        if (!sym) {
            fprintf(stderr, "cannot load %s: %s\n", lib_path, dlerror());
            return 1;
        }
        memcpy(&entry, &sym, sizeof entry);
    }
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    vfx_context *ctx = NULL;
    if (entry(VFX_ABI_VERSION, &host, &api) != VFX_OK || api.create(&host, &ctx) != VFX_OK) {
        fprintf(stderr, "plugin: %s\n", ctx ? api.last_error(ctx, NULL) : "create failed");
        return 1;
    }
    if (api.resize(ctx, W, H) != VFX_OK)
        return 1;

    /* the game's targets: its opaque pass (sky and a floor at y = -1.2 in depth), the image it
     * presents, and the window's default framebuffer */
    GLuint scene_c, scene_d, out_c, scene_fbo, out_fbo;
    gl.CreateTextures(GL_TEXTURE_2D, 1, &scene_c);
    gl.TextureStorage2D(scene_c, 1, GL_RGBA8, W, H);
    gl.CreateTextures(GL_TEXTURE_2D, 1, &scene_d);
    gl.TextureStorage2D(scene_d, 1, GL_DEPTH_COMPONENT24, W, H);
    gl.CreateTextures(GL_TEXTURE_2D, 1, &out_c);
    gl.TextureStorage2D(out_c, 1, GL_RGBA8, W, H);
    gl.CreateFramebuffers(1, &scene_fbo);
    gl.NamedFramebufferTexture(scene_fbo, GL_COLOR_ATTACHMENT0, scene_c, 0);
    gl.NamedFramebufferTexture(scene_fbo, GL_DEPTH_ATTACHMENT, scene_d, 0);
    gl.CreateFramebuffers(1, &out_fbo);
    gl.NamedFramebufferTexture(out_fbo, GL_COLOR_ATTACHMENT0, out_c, 0);

    /* camera at (0, 0.6, 5) looking at (0, -0.2, 0), 55 degrees */
    float eye[3] = {0, 0.6f, 5}, at[3] = {0, -0.2f, 0};
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]};
    float fl = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; ++k)
        f[k] /= fl;
    float s[3] = {-f[2], 0, f[0]}; /* f x up(0,1,0) */
    float sl = sqrtf(s[0] * s[0] + s[2] * s[2]);
    s[0] /= sl, s[2] /= sl;
    float u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
    float fov = 0.96f, n = 0.1f, fa = 60, t = 1 / tanf(0.5f * fov);
    vfx_frame_view fv = {
        .type = VFX_TYPE_FRAME_VIEW, .framebuffer = out_fbo, .color_texture = scene_c,
        .depth_texture = scene_d, .width = W, .height = H,
        .view = {s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
                 -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]), -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]),
                 f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2], 1},
        .proj = {t * H / W, 0, 0, 0, 0, t, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0, -2 * fa * n / (fa - n), 0},
        .eye = {eye[0], eye[1], eye[2]}, .near_plane = n, .far_plane = fa, .fov_y = fov};

    int rc = 0;
    for (int frame = 0; frame < frames && rc == 0; ++frame) {
        SDL_Event ev;
        while (SDL_PollEvent(&ev))
            if (ev.type == SDL_QUIT)
                frames = frame;
        step(&g, 1.f / 60.f);
        gl.ClearNamedFramebufferfv(scene_fbo, GL_COLOR, 0, (const float[4]){0.30f, 0.36f, 0.44f, 1});
        gl.ClearNamedFramebufferfv(scene_fbo, GL_DEPTH, 0, (const float[1]){1});
        gl.BlitNamedFramebuffer(scene_fbo, out_fbo, 0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        if (api.update(ctx, frame / 60.0, 1.f / 60.f) != VFX_OK || api.render(ctx, &fv) != VFX_OK) {
            fprintf(stderr, "frame %d: %s\n", frame, api.last_error(ctx, NULL));
            rc = 1;
            break;
        }
        gl.BlitNamedFramebuffer(out_fbo, 0, 0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        SDL_GL_SwapWindow(win);
    }
    /* Each effect drew where the game put it: water in the middle, beams in the upper half,
     * the volume to the right. */
    static float raw[W * H];
    int water = 0, beams = 0, volume = 0;
    if (rc == 0 && api.read_raw(ctx, VFX_EFFECT_WATER, raw, W * H) == VFX_OK)
        water = covered(raw, W / 3, 2 * W / 3, 0.0f);
    if (rc == 0 && api.read_raw(ctx, VFX_EFFECT_BEAMS, raw, W * H) == VFX_OK)
        beams = covered(raw, 0, W, 1e-3f);
    if (rc == 0 && api.read_raw(ctx, VFX_EFFECT_VOLUME, raw, W * H) == VFX_OK)
        volume = covered(raw, 2 * W / 3, W, 1e-3f);
    printf("%d frames: water %d px, beams %d px, volume %d px, %d errors\n", frames, water, beams, volume, g.errors);
    if (ppm && rc == 0) {
        static unsigned char px[W * H * 4];
        gl.GetTextureImage(out_c, 0, GL_RGBA, GL_UNSIGNED_BYTE, sizeof px, px);
        FILE *o = fopen(ppm, "wb");
        if (o) {
            fprintf(o, "P6 %d %d 255\n", W, H);
            for (int y = H - 1; y >= 0; --y)
                for (int x = 0; x < W; ++x)
                    fwrite(&px[4 * (y * W + x)], 1, 3, o);
            fclose(o);
        }
    }
    api.destroy(ctx);
    gl.DeleteFramebuffers(1, &scene_fbo);
    gl.DeleteFramebuffers(1, &out_fbo);
    GLuint texs[3] = {scene_c, scene_d, out_c};
    gl.DeleteTextures(3, texs);
    if (lib)
        dlclose(lib);
    SDL_GL_DeleteContext(glc);
    SDL_DestroyWindow(win);
    SDL_Quit();
    if (rc || g.errors)
        return 1;
    uint32_t want = api.effects_built;
    bool ok = (!(want & VFX_EFFECT_BIT(VFX_EFFECT_WATER)) || water > 200)
              && (!(want & VFX_EFFECT_BIT(VFX_EFFECT_BEAMS)) || beams > 200)
              && (!(want & VFX_EFFECT_BIT(VFX_EFFECT_VOLUME)) || volume > 100);
    return ok ? 0 : 1;
}
