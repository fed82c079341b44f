// cpp_host.cpp — a C++20 engine's host: every ABI struct filled with designated initializers
// (no casts, no size or version fields), then the minimal path: create, update and render one
// frame on a headless EGL context, a pixel checked, stats, lights and resolved defaults read back.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <volfx/volfx.h>

namespace {

constexpr int W = 96, H = 64, NP = 512;

struct game {
    float x[NP], y[NP], z[NP], vx[NP], vy[NP], vz[NP];
    vfx_beam beams[1];
    float points[12] = {-0.5f, -0.5f, -1, 0.5f, -0.5f, -1, 0, 0.5f, -1, 0, 0, -0.2f};
    uint32_t tets[4] = {0, 1, 2, 3};
    float scalar[4] = {0, 1, 2, 3};
    int errors = 0;
};

void on_log(void *user, vfx_log_level level, vfx_log_id id, const char *msg)
{
    auto *g = static_cast<game *>(user);
    if (level >= VFX_LOG_WARN)
    {
        const char *name = vfx_log_id_name(id); // NULL: an id newer than this header
        std::fprintf(stderr, "volfx (%s, id %d): %s\n", name ? name : "?", static_cast<int>(id), msg);
    }
    if (level == VFX_LOG_ERROR)
        g->errors++;
}
void *on_proc(void *, const char *name) { return reinterpret_cast<void *>(eglGetProcAddress(name)); }
uint32_t on_chunks(void *) { return 1; }
vfx_result on_chunk(void *user, uint32_t, vfx_particle_view *v)
{
    auto *g = static_cast<game *>(user);
    *v = vfx_particle_view{.type = VFX_TYPE_PARTICLE_VIEW, .next = nullptr, .count = NP,
                           .pos = {g->x, g->y, g->z}, .vel = {g->vx, g->vy, g->vz}, .radius = nullptr,
                           .kernel = nullptr, .revision = 1,
                           .gpu_pos = {.buffer = 0, .stride = 0, .offset = 0}, .gpu_vel = {}, .gpu_kernel = {}};
    return VFX_OK;
}
vfx_result on_water(void *, vfx_water_params *p)
{
    *p = vfx_water_params{.type = VFX_TYPE_WATER_PARAMS, .next = nullptr, .h = 0, .threshold = 0,
                          .features_off = VFX_WATER_NO_SSR, .method = VFX_WATER_METHOD_TILE,
                          .color = {0.1f, 0.5f, 0.6f}, .preset = VFX_WATER_PRESET_LOW,
                          .kernel = VFX_WATER_KERNEL_DEFAULT, .gravity = {0, -9.81f, 0}};
    return VFX_OK;
}
vfx_result on_beams(void *user, vfx_beams_view *v)
{
    auto *g = static_cast<game *>(user);
    *v = vfx_beams_view{.type = VFX_TYPE_BEAMS_VIEW, .next = nullptr, .count = 1,
                        .saturation = VFX_SATURATE_SMOOTH, .beams = g->beams, .saturate_c = 1,
                        .far_distance = 0, .bloom = VFX_BEAMS_BLOOM_OFF};
    return VFX_OK;
}
uint32_t on_volumes(void *) { return 1; }
vfx_result on_volume(void *user, uint32_t, vfx_volume_view *v)
{
    auto *g = static_cast<game *>(user);
    *v = vfx_volume_view{.type = VFX_TYPE_VOLUME_VIEW, .next = nullptr, .point_count = 4, .tet_count = 1,
                         .points = g->points, .tets = g->tets, .scalar = g->scalar, .scalar_min = 0,
                         .scalar_max = 3, .transfer_rgba = nullptr, .transfer_count = 0,
                         .transfer_method = VFX_VOLUME_TRANSFER_EXACT, .workers = 1, .revision = 1};
    return VFX_OK;
}

bool make_context()
{
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d == EGL_NO_DISPLAY || !eglInitialize(d, nullptr, nullptr) || !eglBindAPI(EGL_OPENGL_API))
        return false;
    const EGLint a[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, a);
    return c != EGL_NO_CONTEXT && eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c);
}

int fail(const char *what)
{
    std::fprintf(stderr, "cpp_host: %s\n", what);
    return 1;
}

} // namespace

int main()
{
    if (!make_context()) {
        std::fprintf(stderr, "no GL 4.5 context: skipping\n");
        return 77;
    }
    static game g;
    for (int i = 0; i < NP; ++i) { // an 8x8x8 block of water in front of the camera
        g.x[i] = -0.6f + 0.15f * static_cast<float>(i % 8);
        g.y[i] = -0.6f + 0.15f * static_cast<float>((i / 8) % 8);
        g.z[i] = -0.6f + 0.15f * static_cast<float>(i / 64);
        g.vx[i] = g.vy[i] = g.vz[i] = 0;
    }
    g.beams[0] = vfx_beam{.type = VFX_TYPE_BEAM, .next = nullptr, .head = {-2, 1.2f, 0}, .length = 4,
                          .dir = {1, 0, 0}, .radius = 0.6f, .a = 0.5f, .b = 0.5f, .eps = 0.05f,
                          .color = {1, 0.5f, 0.2f, 1}, .falloff = VFX_BEAM_FALLOFF_SMOOTH,
                          .ramp = VFX_BEAM_RAMP_HOT, .intensity = 1, .flow_kind = VFX_BEAM_FLOW_NOISE};
    const vfx_context_desc desc{.type = VFX_TYPE_CONTEXT_DESC, .next = nullptr, .user = &g,
                                .gl_get_proc_address = on_proc, .log = on_log, .alloc = nullptr,
                                .free = nullptr, .particle_chunk_count = on_chunks,
                                .particle_chunk = on_chunk, .water_params = on_water, .beams = on_beams,
                                .volume_count = on_volumes, .volume = on_volume};
    vfx_plugin_api api{.type = VFX_TYPE_PLUGIN_API, .next = nullptr};
    if (vfx_plugin_entry(VFX_ABI_VERSION, &desc, &api) != VFX_OK)
        return fail("entry refused the host");
    vfx_context *ctx = nullptr;
    if (api.create(&desc, &ctx) != VFX_OK)
        return fail("create failed");
    GLuint scene_c, scene_d, out_c, out_fbo, scene_fbo;
    glCreateTextures(GL_TEXTURE_2D, 1, &scene_c);
    glTextureStorage2D(scene_c, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &scene_d);
    glTextureStorage2D(scene_d, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &out_c);
    glTextureStorage2D(out_c, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &scene_fbo);
    glNamedFramebufferTexture(scene_fbo, GL_COLOR_ATTACHMENT0, scene_c, 0);
    glNamedFramebufferTexture(scene_fbo, GL_DEPTH_ATTACHMENT, scene_d, 0);
    glCreateFramebuffers(1, &out_fbo);
    glNamedFramebufferTexture(out_fbo, GL_COLOR_ATTACHMENT0, out_c, 0);
    const float clear[4] = {0, 0, 0, 1}, one = 1;
    glClearNamedFramebufferfv(scene_fbo, GL_COLOR, 0, clear);
    glClearNamedFramebufferfv(scene_fbo, GL_DEPTH, 0, &one);
    glBlitNamedFramebuffer(scene_fbo, out_fbo, 0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    const float f = 1.f / std::tan(0.5f * 1.0472f), n = 0.1f, fa = 50.f;
    const vfx_frame_view fv{.type = VFX_TYPE_FRAME_VIEW, .next = nullptr, .framebuffer = out_fbo,
                            .color_texture = scene_c, .depth_texture = scene_d, .width = W, .height = H,
                            .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -4, 1},
                            .proj = {f * H / W, 0, 0, 0, 0, f, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0,
                                     -2 * fa * n / (fa - n), 0},
                            .eye = {0, 0, 4}, .near_plane = n, .far_plane = fa, .fov_y = 1.0472f,
                            .effects = 0, .origin = {0, 0, 0}, .color_hdr = 0, .environment_cubemap = 0,
                            .view_id = 0, .layer_texture = 0};
    if (api.update(ctx, 0.0, 1.f / 60.f) != VFX_OK || api.render(ctx, &fv) != VFX_OK) {
        std::fprintf(stderr, "frame: %s\n", api.last_error(ctx, nullptr));
        return 1;
    }
    static unsigned char px[W * H * 4];
    glGetTextureImage(out_c, 0, GL_RGBA, GL_UNSIGNED_BYTE, sizeof px, px);
    int lit = 0;
    for (int i = 0; i < W * H; ++i)
        lit += px[4 * i] + px[4 * i + 1] + px[4 * i + 2] > 30;
    static vfx_stats st{.type = VFX_TYPE_STATS, .next = nullptr, .count = 0, .dropped = 0, .entries = {}};
    vfx_light lights[8]{};
    vfx_lights ls{.type = VFX_TYPE_LIGHTS, .next = nullptr, .capacity = 8, .count = 0, .total = 0, .lights = lights};
    vfx_water_params wp{.type = VFX_TYPE_WATER_PARAMS, .next = nullptr, .h = 0.2f};
    if (api.get_stats(ctx, &st) != VFX_OK || api.get_lights(ctx, &ls) != VFX_OK
        || api.resolve_defaults(ctx, &wp) != VFX_OK)
        return fail(api.last_error(ctx, nullptr));
    std::printf("C++ host: %d of %d pixels lit, %u stats, %u lights, resolved step %g (h/8), %d errors\n", lit,
                W * H, st.count, ls.count, static_cast<double>(wp.step), g.errors);
    api.destroy(ctx);
    const uint32_t drawn = VFX_EFFECT_BIT(VFX_EFFECT_WATER) | VFX_EFFECT_BIT(VFX_EFFECT_BEAMS);
    if (g.errors || st.count == 0 || std::fabs(wp.step - 0.2f / 8) > 1e-7f)
        return 1;
    return (api.effects_built & drawn) ? (lit > 0 ? 0 : 1) : (lit == 0 ? 0 : 1);
}
