/* vulkan_host.c — volfx in a Vulkan engine. The engine renders its opaque scene with Vulkan
 * (lavapipe here) into Vulkan-owned colour and depth images; a GL 4.5 context on the same device
 * imports those images and the output image through GL_EXT_memory_object_fd, and the plugin
 * draws its effects into them with GL. Nothing from runtime/ (docs/integration.md, "A Vulkan
 * engine").
 *
 * Synchronisation: Mesa's llvmpipe has GL_EXT_memory_object_fd but no GL_EXT_semaphore, so the
 * hand-over is CPU-side: Vulkan submits with a fence and waits for it before GL touches the
 * images, GL ends with glFinish before Vulkan reads them again. A driver with
 * GL_EXT_semaphore_fd does it on the GPU instead: two exported VkSemaphores imported with
 * glImportSemaphoreFdEXT, glWaitSemaphoreEXT (with the images' layouts) before the plugin's
 * render and glSignalSemaphoreEXT after it, and Vulkan waits on the second before it reads.
 *
 * Check: the same scene (same triangles, same shader source) rendered by a plain GL host with
 * GL-owned textures, the same effects over it; each effect's coverage (read_raw) and the final
 * image of the Vulkan path must match the GL path's.
 * usage: vulkan_host [--ppm PREFIX]  (writes PREFIX-vulkan.ppm and PREFIX-gl.ppm)
 * Exits 0 on a match, 1 on a mismatch or any error, 77 when no GL 4.5 context can be made. */
#include <dlfcn.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <vulkan/vulkan.h>

#include <volfx/volfx.h>

/* SPIR-V of shaders/vulkan_host/scene.{vert,frag}, compiled at build time by glslc -mfmt=c */
static const uint32_t scene_vert_spv[] =
#include "vulkan_scene_vert.spv.inc"
    ;
static const uint32_t scene_frag_spv[] =
#include "vulkan_scene_frag.spv.inc"
    ;
#include "vulkan_scene_glsl.h" /* the same two files as GLSL text for the GL reference */

enum { W = 160, H = 96, NP = 512, FRAMES = 3, VERT_FLOATS = 7 };

/* ------------------------------------------------------------------ the game's data */

typedef struct game {
    float x[NP], y[NP], z[NP];
    vfx_beam beam;
    float points[8 * 3], scalar[8];
    uint32_t tets[5 * 4];
    float verts[12 * VERT_FLOATS]; /* the opaque scene, clip space: floor + pillar, 4 triangles */
    uint64_t frame;
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
static void *on_proc(void *user, const char *name) { (void)user; return (void *)eglGetProcAddress(name); }
static uint32_t on_chunks(void *user) { (void)user; return 1; }
static vfx_result on_chunk(void *user, uint32_t i, vfx_particle_view *v)
{
    game *g = user;
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    v->count = NP;
    v->pos[0] = g->x, v->pos[1] = g->y, v->pos[2] = g->z;
    v->revision = 1;
    return VFX_OK;
}
static vfx_result on_beams(void *user, vfx_beams_view *v)
{
    game *g = user;
    v->count = 1;
    v->beams = &g->beam;
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

/* camera at (0, 0, 4) looking down -z, 60 degrees, OpenGL conventions (column-major) */
static vfx_frame_view camera(void)
{
    float f = 1.f / tanf(0.5f * 1.0472f), n = 0.1f, fa = 50.f;
    return (vfx_frame_view){.type = VFX_TYPE_FRAME_VIEW, .width = W, .height = H,
                            .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -4, 1},
                            .proj = {f * H / W, 0, 0, 0, 0, f, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0, -2 * fa * n / (fa - n), 0},
                            .eye = {0, 0, 4}, .near_plane = n, .far_plane = fa, .fov_y = 1.0472f};
}

/* One world-space vertex to clip space (proj * view) with its colour. */
static void put_vertex(float *out, const vfx_frame_view *c, float x, float y, float z, const float rgb[3])
{
    float p[4] = {x, y, z, 1}, v[4], q[4];
    for (int r = 0; r < 4; ++r)
        v[r] = c->view[r] * p[0] + c->view[4 + r] * p[1] + c->view[8 + r] * p[2] + c->view[12 + r] * p[3];
    for (int r = 0; r < 4; ++r)
        q[r] = c->proj[r] * v[0] + c->proj[4 + r] * v[1] + c->proj[8 + r] * v[2] + c->proj[12 + r] * v[3];
    memcpy(out, q, sizeof q);
    memcpy(out + 4, rgb, 3 * sizeof(float));
}

/* A quad as two triangles; corners in order around it. */
static float *put_quad(float *out, const vfx_frame_view *c, const float q[4][3], const float rgb[2][3])
{
    static const int idx[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; ++k, out += VERT_FLOATS)
        put_vertex(out, c, q[idx[k]][0], q[idx[k]][1], q[idx[k]][2], rgb[idx[k] >= 2]);
    return out;
}

static void setup(game *g)
{
    for (int i = 0; i < NP; ++i) { /* an 8x8x8 block of water, its bottom below the floor */
        g->x[i] = -0.6f + 0.15f * (float)(i % 8);
        g->y[i] = -1.0f + 0.15f * (float)((i / 8) % 8);
        g->z[i] = -0.6f + 0.15f * (float)(i / 64);
    }
    g->beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-2, 1.2f, 0}, .dir = {1, 0, 0}, .length = 4, .radius = 0.6f,
                         .a = 0.5f, .b = 0.5f, .eps = 0.05f, .color = {1.0f, 0.6f, 0.3f, 1}};
    for (int i = 0; i < 8; ++i) { /* a unit cube of 5 tetrahedra at the right, half under the floor */
        g->points[3 * i + 0] = 1.3f + 0.9f * (float)(i & 1);
        g->points[3 * i + 1] = -1.3f + 0.9f * (float)((i >> 1) & 1);
        g->points[3 * i + 2] = -0.9f + 0.9f * (float)((i >> 2) & 1);
        g->scalar[i] = (float)((i >> 1) & 1);
    }
    static const uint32_t t[20] = {0, 1, 2, 4, 1, 2, 3, 7, 1, 4, 5, 7, 2, 4, 6, 7, 1, 2, 4, 7};
    memcpy(g->tets, t, sizeof t);
    /* the opaque scene: a floor at y = -0.9 (depth varies across it) and a pillar in front of the
     * water and across the beam */
    vfx_frame_view c = camera();
    static const float floor_q[4][3] = {{-5, -0.9f, 2.5f}, {5, -0.9f, 2.5f}, {5, -0.9f, -6}, {-5, -0.9f, -6}};
    static const float floor_c[2][3] = {{0.32f, 0.28f, 0.22f}, {0.16f, 0.2f, 0.26f}};
    static const float pillar_q[4][3] = {{-0.2f, -0.9f, 1}, {0.2f, -0.9f, 1}, {0.2f, 2.4f, 1}, {-0.2f, 2.4f, 1}};
    static const float pillar_c[2][3] = {{0.5f, 0.2f, 0.16f}, {0.7f, 0.35f, 0.25f}};
    put_quad(put_quad(g->verts, &c, floor_q, floor_c), &c, pillar_q, pillar_c);
}

static const float sky[4] = {0.35f, 0.4f, 0.45f, 1};

/* ------------------------------------------------------------------------- GL side */

static bool make_context(void)
{
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (d == EGL_NO_DISPLAY || !eglInitialize(d, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API))
        return false;
    const EGLint a[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, a);
    return c != EGL_NO_CONTEXT && eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c);
}

/* The targets one path hands the plugin: scene colour + depth, and the output it presents. */
typedef struct targets {
    GLuint color, depth, out, out_fbo;
} targets;

static void make_output_fbo(targets *t)
{
    glCreateFramebuffers(1, &t->out_fbo);
    glNamedFramebufferTexture(t->out_fbo, GL_COLOR_ATTACHMENT0, t->out, 0);
}

/* The GL reference host's scene: the same vertices through the same shader source. */
typedef struct gl_scene {
    GLuint prog, vao, vbo, fbo;
    targets t;
} gl_scene;

static GLuint compile(GLenum stage, const char *src)
{
    GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "GL scene shader: %s\n", log);
    }
    return s;
}

static bool gl_scene_create(gl_scene *s, const game *g)
{
    GLuint vs = compile(GL_VERTEX_SHADER, scene_vert_glsl), fs = compile(GL_FRAGMENT_SHADER, scene_frag_glsl);
    s->prog = glCreateProgram();
    glAttachShader(s->prog, vs);
    glAttachShader(s->prog, fs);
    glLinkProgram(s->prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(s->prog, GL_LINK_STATUS, &ok);
    if (!ok)
        return false;
    glCreateBuffers(1, &s->vbo);
    glNamedBufferStorage(s->vbo, sizeof g->verts, g->verts, 0);
    glCreateVertexArrays(1, &s->vao);
    glVertexArrayVertexBuffer(s->vao, 0, s->vbo, 0, VERT_FLOATS * sizeof(float));
    glEnableVertexArrayAttrib(s->vao, 0);
    glEnableVertexArrayAttrib(s->vao, 1);
    glVertexArrayAttribFormat(s->vao, 0, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(s->vao, 1, 3, GL_FLOAT, GL_FALSE, 4 * sizeof(float));
    glVertexArrayAttribBinding(s->vao, 0, 0);
    glVertexArrayAttribBinding(s->vao, 1, 0);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->t.color);
    glTextureStorage2D(s->t.color, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->t.depth);
    glTextureStorage2D(s->t.depth, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->t.out);
    glTextureStorage2D(s->t.out, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &s->fbo);
    glNamedFramebufferTexture(s->fbo, GL_COLOR_ATTACHMENT0, s->t.color, 0);
    glNamedFramebufferTexture(s->fbo, GL_DEPTH_ATTACHMENT, s->t.depth, 0);
    make_output_fbo(&s->t);
    return glCheckNamedFramebufferStatus(s->fbo, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

static void gl_scene_draw(gl_scene *s)
{
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    glViewport(0, 0, W, H);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glClearNamedFramebufferfv(s->fbo, GL_COLOR, 0, sky);
    glClearNamedFramebufferfv(s->fbo, GL_DEPTH, 0, (const float[1]){1});
    glUseProgram(s->prog);
    glBindVertexArray(s->vao);
    glDrawArrays(GL_TRIANGLES, 0, 12);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
    glBlitNamedFramebuffer(s->fbo, s->t.out_fbo, 0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

static void gl_scene_destroy(gl_scene *s)
{
    GLuint tex[3] = {s->t.color, s->t.depth, s->t.out}, fbo[2] = {s->fbo, s->t.out_fbo};
    glDeleteTextures(3, tex);
    glDeleteFramebuffers(2, fbo);
    glDeleteBuffers(1, &s->vbo);
    glDeleteVertexArrays(1, &s->vao);
    glDeleteProgram(s->prog);
}

/* ------------------------------------------------------------------------- Vulkan side */

typedef struct shared_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkDeviceSize size;
    GLuint gl_memory, gl_texture;
} shared_image;

typedef struct vk {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice phys;
    VkDevice dev;
    VkQueue queue;
    uint32_t family;
    PFN_vkGetMemoryFdKHR get_memory_fd;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence fence;
    shared_image color, depth, out;
    VkRenderPass pass;
    VkFramebuffer fb;
    VkPipelineLayout layout;
    VkPipeline pipe;
    VkBuffer vbuf, rbuf;
    VkDeviceMemory vmem, rmem;
    void *rmap;
    int validation_errors;
    targets t; /* GL names of the imported images */
} vk;

#define VK_TRY(call)                                                                                \
    do {                                                                                            \
        VkResult r_ = (call);                                                                       \
        if (r_ != VK_SUCCESS) {                                                                     \
            fprintf(stderr, "%s:%d: %s failed (VkResult %d)\n", __FILE__, __LINE__, #call, (int)r_); \
            return false;                                                                           \
        }                                                                                           \
    } while (0)

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT sev,
                                                    VkDebugUtilsMessageTypeFlagsEXT type,
                                                    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)type;
    vk *v = user;
    if (sev >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)
        fprintf(stderr, "vulkan validation: %s\n", data->pMessage);
    if (sev >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)
        v->validation_errors++;
    return VK_FALSE;
}

static bool has_layer(const char *name)
{
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, NULL);
    VkLayerProperties *l = calloc(n ? n : 1, sizeof *l);
    vkEnumerateInstanceLayerProperties(&n, l);
    bool found = false;
    for (uint32_t i = 0; i < n; ++i)
        found = found || strcmp(l[i].layerName, name) == 0;
    free(l);
    return found;
}

/* Instance with the Khronos validation layer when it is installed (vulkan-validationlayers) and
 * VFX_VK_VALIDATION is not 0: any validation error fails the test. */
static bool vk_instance(vk *v)
{
    /* Leak checking only (VFX_EGL_KEEP_DRIVER, scripts/test-sanitize.sh): vkDestroyInstance
     * unloads lavapipe and the layer, after which LeakSanitizer cannot name their
     * process-lifetime allocations for tests/lsan-gl.supp; pinning them keeps the names. */
    if (getenv("VFX_EGL_KEEP_DRIVER")) {
        dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_NODELETE);
        dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_NODELETE);
    }
    const char *env = getenv("VFX_VK_VALIDATION");
    bool validate = (!env || strcmp(env, "0") != 0) && has_layer("VK_LAYER_KHRONOS_validation");
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .pApplicationName = "volfx vulkan_host",
                             .apiVersion = VK_API_VERSION_1_1};
    VkDebugUtilsMessengerCreateInfoEXT mi = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT,
        .pfnUserCallback = on_validation, .pUserData = v};
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app,
                               .enabledLayerCount = validate ? 1u : 0u, .ppEnabledLayerNames = layers,
                               .enabledExtensionCount = validate ? 1u : 0u, .ppEnabledExtensionNames = exts,
                               .pNext = validate ? &mi : NULL};
    VK_TRY(vkCreateInstance(&ci, NULL, &v->instance));
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(v->instance, "vkCreateDebugUtilsMessengerEXT");
        if (create)
            VK_TRY(create(v->instance, &mi, NULL, &v->messenger));
    }
    printf("vulkan: validation layer %s\n", validate ? "on" : "off (not installed or VFX_VK_VALIDATION=0)");
    return true;
}

/* The Vulkan device that is the GL context's device: the one whose deviceUUID and driverUUID
 * equal GL_DEVICE_UUID_EXT and GL_DRIVER_UUID_EXT (memory exported by one can be imported by
 * the other only then). */
static bool vk_pick_device(vk *v)
{
    GLubyte gl_dev[GL_UUID_SIZE_EXT] = {0}, gl_drv[GL_UUID_SIZE_EXT] = {0};
    glGetUnsignedBytei_vEXT(GL_DEVICE_UUID_EXT, 0, gl_dev);
    glGetUnsignedBytevEXT(GL_DRIVER_UUID_EXT, gl_drv);
    uint32_t n = 0;
    VK_TRY(vkEnumeratePhysicalDevices(v->instance, &n, NULL));
    VkPhysicalDevice devs[16];
    n = n > 16 ? 16 : n;
    VK_TRY(vkEnumeratePhysicalDevices(v->instance, &n, devs));
    for (uint32_t i = 0; i < n; ++i) {
        VkPhysicalDeviceIDProperties id = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
        VkPhysicalDeviceProperties2 p = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &id};
        vkGetPhysicalDeviceProperties2(devs[i], &p);
        if (memcmp(id.deviceUUID, gl_dev, VK_UUID_SIZE) == 0 && memcmp(id.driverUUID, gl_drv, VK_UUID_SIZE) == 0) {
            v->phys = devs[i];
            printf("vulkan: %s, the GL context's device (UUIDs match)\n", p.properties.deviceName);
            return true;
        }
    }
    fprintf(stderr, "vulkan: none of %u devices has the GL context's device and driver UUID (%s)\n", n,
            (const char *)glGetString(GL_RENDERER));
    return false;
}

static bool vk_device(vk *v)
{
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(v->phys, &n, NULL);
    VkQueueFamilyProperties fam[16];
    n = n > 16 ? 16 : n;
    vkGetPhysicalDeviceQueueFamilyProperties(v->phys, &n, fam);
    v->family = UINT32_MAX;
    for (uint32_t i = 0; i < n && v->family == UINT32_MAX; ++i)
        if (fam[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)
            v->family = i;
    if (v->family == UINT32_MAX)
        return false;
    float prio = 1;
    VkDeviceQueueCreateInfo q = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, .queueFamilyIndex = v->family,
                                 .queueCount = 1, .pQueuePriorities = &prio};
    const char *exts[] = {VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME};
    VkDeviceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .queueCreateInfoCount = 1,
                             .pQueueCreateInfos = &q, .enabledExtensionCount = 1, .ppEnabledExtensionNames = exts};
    VK_TRY(vkCreateDevice(v->phys, &ci, NULL, &v->dev));
    vkGetDeviceQueue(v->dev, v->family, 0, &v->queue);
    v->get_memory_fd = (PFN_vkGetMemoryFdKHR)vkGetDeviceProcAddr(v->dev, "vkGetMemoryFdKHR");
    VkCommandPoolCreateInfo pc = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                  .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queueFamilyIndex = v->family};
    VK_TRY(vkCreateCommandPool(v->dev, &pc, NULL, &v->pool));
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, .commandPool = v->pool,
                                      .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, .commandBufferCount = 1};
    VK_TRY(vkAllocateCommandBuffers(v->dev, &ai, &v->cmd));
    VkFenceCreateInfo fc = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_TRY(vkCreateFence(v->dev, &fc, NULL, &v->fence));
    return v->get_memory_fd != NULL;
}

static uint32_t memory_type(const vk *v, uint32_t bits, VkMemoryPropertyFlags want)
{
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(v->phys, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want)
            return i;
    return UINT32_MAX;
}

/* An image Vulkan owns and GL can import: external-memory create info, a dedicated exportable
 * allocation, an opaque fd handed to GL (which then owns the fd), the same format and size as a
 * GL texture over the memory object. */
static bool shared_image_create(vk *v, shared_image *s, VkFormat format, GLenum gl_format, VkImageUsageFlags usage,
                                VkImageAspectFlags aspect)
{
    VkPhysicalDeviceExternalImageFormatInfo ext_info = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_IMAGE_FORMAT_INFO,
                                                        .handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT};
    VkPhysicalDeviceImageFormatInfo2 fi = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2, .pNext = &ext_info,
                                           .format = format, .type = VK_IMAGE_TYPE_2D, .tiling = VK_IMAGE_TILING_OPTIMAL,
                                           .usage = usage};
    VkExternalImageFormatProperties ext_props = {.sType = VK_STRUCTURE_TYPE_EXTERNAL_IMAGE_FORMAT_PROPERTIES};
    VkImageFormatProperties2 fp = {.sType = VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2, .pNext = &ext_props};
    VK_TRY(vkGetPhysicalDeviceImageFormatProperties2(v->phys, &fi, &fp));
    if (!(ext_props.externalMemoryProperties.externalMemoryFeatures & VK_EXTERNAL_MEMORY_FEATURE_EXPORTABLE_BIT)) {
        fprintf(stderr, "vulkan: format %d cannot be exported as an opaque fd\n", (int)format);
        return false;
    }
    VkExternalMemoryImageCreateInfo ext_img = {.sType = VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO,
                                               .handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT};
    VkImageCreateInfo ic = {.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, .pNext = &ext_img, .imageType = VK_IMAGE_TYPE_2D,
                            .format = format, .extent = {W, H, 1}, .mipLevels = 1, .arrayLayers = 1,
                            .samples = VK_SAMPLE_COUNT_1_BIT, .tiling = VK_IMAGE_TILING_OPTIMAL, .usage = usage,
                            .sharingMode = VK_SHARING_MODE_EXCLUSIVE, .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED};
    VK_TRY(vkCreateImage(v->dev, &ic, NULL, &s->image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(v->dev, s->image, &req);
    VkMemoryDedicatedAllocateInfo ded = {.sType = VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO, .image = s->image};
    VkExportMemoryAllocateInfo exp = {.sType = VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO, .pNext = &ded,
                                      .handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT};
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .pNext = &exp, .allocationSize = req.size,
                               .memoryTypeIndex = memory_type(v, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)};
    if (ai.memoryTypeIndex == UINT32_MAX)
        return false;
    VK_TRY(vkAllocateMemory(v->dev, &ai, NULL, &s->memory));
    VK_TRY(vkBindImageMemory(v->dev, s->image, s->memory, 0));
    s->size = req.size;
    VkImageViewCreateInfo vc = {.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, .image = s->image,
                                .viewType = VK_IMAGE_VIEW_TYPE_2D, .format = format,
                                .subresourceRange = {aspect, 0, 1, 0, 1}};
    VK_TRY(vkCreateImageView(v->dev, &vc, NULL, &s->view));
    int fd = -1;
    VkMemoryGetFdInfoKHR gi = {.sType = VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR, .memory = s->memory,
                               .handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT};
    VK_TRY(v->get_memory_fd(v->dev, &gi, &fd));
    /* GL side: a memory object over the fd (GL owns the fd from here), marked dedicated as the
     * Vulkan allocation is, and a texture of the same format and size at offset 0 */
    glCreateMemoryObjectsEXT(1, &s->gl_memory);
    GLint dedicated = GL_TRUE;
    glMemoryObjectParameterivEXT(s->gl_memory, GL_DEDICATED_MEMORY_OBJECT_EXT, &dedicated);
    glImportMemoryFdEXT(s->gl_memory, s->size, GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd);
    glCreateTextures(GL_TEXTURE_2D, 1, &s->gl_texture);
    glTextureStorageMem2DEXT(s->gl_texture, 1, gl_format, W, H, s->gl_memory, 0);
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        fprintf(stderr, "GL: importing the Vulkan image (format 0x%x) failed: GL error 0x%x\n", gl_format, e);
        return false;
    }
    return true;
}

static void shared_image_destroy(vk *v, shared_image *s)
{
    glDeleteTextures(1, &s->gl_texture);
    glDeleteMemoryObjectsEXT(1, &s->gl_memory);
    vkDestroyImageView(v->dev, s->view, NULL);
    vkDestroyImage(v->dev, s->image, NULL);
    vkFreeMemory(v->dev, s->memory, NULL);
}

static bool vk_buffer(vk *v, VkDeviceSize size, VkBufferUsageFlags usage, VkBuffer *buf, VkDeviceMemory *mem, void **map)
{
    VkBufferCreateInfo bc = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, .size = size, .usage = usage,
                             .sharingMode = VK_SHARING_MODE_EXCLUSIVE};
    VK_TRY(vkCreateBuffer(v->dev, &bc, NULL, buf));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(v->dev, *buf, &req);
    VkMemoryAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, .allocationSize = req.size,
                               .memoryTypeIndex = memory_type(v, req.memoryTypeBits,
                                                              VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)};
    if (ai.memoryTypeIndex == UINT32_MAX)
        return false;
    VK_TRY(vkAllocateMemory(v->dev, &ai, NULL, mem));
    VK_TRY(vkBindBufferMemory(v->dev, *buf, *mem, 0));
    VK_TRY(vkMapMemory(v->dev, *mem, 0, size, 0, map));
    return true;
}

static bool vk_shader(vk *v, const uint32_t *code, size_t bytes, VkShaderModule *out)
{
    VkShaderModuleCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, .codeSize = bytes, .pCode = code};
    VK_TRY(vkCreateShaderModule(v->dev, &ci, NULL, out));
    return true;
}

/* Render pass (clear, store; both images end in GENERAL, the layout GL is assumed to see when no
 * semaphore can tell it one), framebuffer and the scene's pipeline. */
static bool vk_pipeline(vk *v)
{
    VkAttachmentDescription att[2] = {
        {.format = VK_FORMAT_R8G8B8A8_UNORM, .samples = VK_SAMPLE_COUNT_1_BIT, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
         .storeOp = VK_ATTACHMENT_STORE_OP_STORE, .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
         .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
         .finalLayout = VK_IMAGE_LAYOUT_GENERAL},
        {.format = VK_FORMAT_D32_SFLOAT, .samples = VK_SAMPLE_COUNT_1_BIT, .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
         .storeOp = VK_ATTACHMENT_STORE_OP_STORE, .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
         .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
         .finalLayout = VK_IMAGE_LAYOUT_GENERAL}};
    VkAttachmentReference cref = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference dref = {1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub = {.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS, .colorAttachmentCount = 1,
                                .pColorAttachments = &cref, .pDepthStencilAttachment = &dref};
    VkRenderPassCreateInfo rc = {.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, .attachmentCount = 2,
                                 .pAttachments = att, .subpassCount = 1, .pSubpasses = &sub};
    VK_TRY(vkCreateRenderPass(v->dev, &rc, NULL, &v->pass));
    VkImageView views[2] = {v->color.view, v->depth.view};
    VkFramebufferCreateInfo fc = {.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO, .renderPass = v->pass,
                                  .attachmentCount = 2, .pAttachments = views, .width = W, .height = H, .layers = 1};
    VK_TRY(vkCreateFramebuffer(v->dev, &fc, NULL, &v->fb));
    VkPipelineLayoutCreateInfo lc = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    VK_TRY(vkCreatePipelineLayout(v->dev, &lc, NULL, &v->layout));
    VkShaderModule vs, fs;
    if (!vk_shader(v, scene_vert_spv, sizeof scene_vert_spv, &vs) || !vk_shader(v, scene_frag_spv, sizeof scene_frag_spv, &fs))
        return false;
    VkPipelineShaderStageCreateInfo st[2] = {
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_VERTEX_BIT, .module = vs, .pName = "main"},
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = fs, .pName = "main"}};
    VkVertexInputBindingDescription bind = {0, VERT_FLOATS * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attr[2] = {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
                                                 {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 4 * sizeof(float)}};
    VkPipelineVertexInputStateCreateInfo vi = {.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
                                               .vertexBindingDescriptionCount = 1, .pVertexBindingDescriptions = &bind,
                                               .vertexAttributeDescriptionCount = 2, .pVertexAttributeDescriptions = attr};
    VkPipelineInputAssemblyStateCreateInfo ia = {.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
                                                 .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
    /* a positive viewport: clip y = -1 goes to memory row 0, which GL samples as its bottom row */
    VkViewport vp = {0, 0, W, H, 0, 1};
    VkRect2D sc = {{0, 0}, {W, H}};
    VkPipelineViewportStateCreateInfo vps = {.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
                                             .viewportCount = 1, .pViewports = &vp, .scissorCount = 1, .pScissors = &sc};
    VkPipelineRasterizationStateCreateInfo rs = {.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
                                                 .polygonMode = VK_POLYGON_MODE_FILL, .cullMode = VK_CULL_MODE_NONE,
                                                 .lineWidth = 1};
    VkPipelineMultisampleStateCreateInfo ms = {.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
                                               .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
    VkPipelineDepthStencilStateCreateInfo ds = {.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
                                                .depthTestEnable = VK_TRUE, .depthWriteEnable = VK_TRUE,
                                                .depthCompareOp = VK_COMPARE_OP_LESS};
    VkPipelineColorBlendAttachmentState cba = {.colorWriteMask = 0xf};
    VkPipelineColorBlendStateCreateInfo cb = {.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
                                              .attachmentCount = 1, .pAttachments = &cba};
    VkGraphicsPipelineCreateInfo pc = {.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, .stageCount = 2,
                                       .pStages = st, .pVertexInputState = &vi, .pInputAssemblyState = &ia,
                                       .pViewportState = &vps, .pRasterizationState = &rs, .pMultisampleState = &ms,
                                       .pDepthStencilState = &ds, .pColorBlendState = &cb, .layout = v->layout,
                                       .renderPass = v->pass};
    VkResult r = vkCreateGraphicsPipelines(v->dev, VK_NULL_HANDLE, 1, &pc, NULL, &v->pipe);
    vkDestroyShaderModule(v->dev, vs, NULL);
    vkDestroyShaderModule(v->dev, fs, NULL);
    VK_TRY(r);
    return true;
}

static bool vk_create(vk *v, const game *g)
{
    if (!vk_instance(v) || !vk_pick_device(v) || !vk_device(v))
        return false;
    const VkImageUsageFlags color_use = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT
                                        | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    if (!shared_image_create(v, &v->color, VK_FORMAT_R8G8B8A8_UNORM, GL_RGBA8, color_use, VK_IMAGE_ASPECT_COLOR_BIT)
        || !shared_image_create(v, &v->depth, VK_FORMAT_D32_SFLOAT, GL_DEPTH_COMPONENT32F,
                                VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                                VK_IMAGE_ASPECT_DEPTH_BIT)
        || !shared_image_create(v, &v->out, VK_FORMAT_R8G8B8A8_UNORM, GL_RGBA8, color_use, VK_IMAGE_ASPECT_COLOR_BIT))
        return false;
    v->t = (targets){.color = v->color.gl_texture, .depth = v->depth.gl_texture, .out = v->out.gl_texture};
    make_output_fbo(&v->t);
    if (glCheckNamedFramebufferStatus(v->t.out_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "GL: the imported output image is not a complete framebuffer\n");
        return false;
    }
    void *vmap;
    if (!vk_buffer(v, sizeof g->verts, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, &v->vbuf, &v->vmem, &vmap)
        || !vk_buffer(v, (VkDeviceSize)W * H * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, &v->rbuf, &v->rmem, &v->rmap))
        return false;
    memcpy(vmap, g->verts, sizeof g->verts);
    return vk_pipeline(v);
}

static void vk_destroy(vk *v)
{
    if (v->dev) {
        vkDeviceWaitIdle(v->dev);
        glDeleteFramebuffers(1, &v->t.out_fbo);
        shared_image_destroy(v, &v->color);
        shared_image_destroy(v, &v->depth);
        shared_image_destroy(v, &v->out);
        vkDestroyPipeline(v->dev, v->pipe, NULL);
        vkDestroyPipelineLayout(v->dev, v->layout, NULL);
        vkDestroyFramebuffer(v->dev, v->fb, NULL);
        vkDestroyRenderPass(v->dev, v->pass, NULL);
        vkDestroyBuffer(v->dev, v->vbuf, NULL);
        vkFreeMemory(v->dev, v->vmem, NULL);
        vkDestroyBuffer(v->dev, v->rbuf, NULL);
        vkFreeMemory(v->dev, v->rmem, NULL);
        vkDestroyFence(v->dev, v->fence, NULL);
        vkDestroyCommandPool(v->dev, v->pool, NULL);
        vkDestroyDevice(v->dev, NULL);
    }
    if (v->messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(v->instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy)
            destroy(v->instance, v->messenger, NULL);
    }
    if (v->instance)
        vkDestroyInstance(v->instance, NULL);
}

static VkImageMemoryBarrier image_barrier(VkImage img, VkImageAspectFlags aspect, VkAccessFlags src, VkAccessFlags dst,
                                          VkImageLayout from, VkImageLayout to, uint32_t src_family, uint32_t dst_family)
{
    return (VkImageMemoryBarrier){.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER, .srcAccessMask = src, .dstAccessMask = dst,
                                  .oldLayout = from, .newLayout = to, .srcQueueFamilyIndex = src_family,
                                  .dstQueueFamilyIndex = dst_family, .image = img, .subresourceRange = {aspect, 0, 1, 0, 1}};
}

/* Submits the recorded command buffer and waits on its fence: the CPU-side hand-over that stands
 * in for a semaphore GL cannot wait on here. */
static bool vk_submit_wait(vk *v)
{
    VK_TRY(vkEndCommandBuffer(v->cmd));
    VkSubmitInfo si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &v->cmd};
    VK_TRY(vkQueueSubmit(v->queue, 1, &si, v->fence));
    VK_TRY(vkWaitForFences(v->dev, 1, &v->fence, VK_TRUE, UINT64_MAX));
    VK_TRY(vkResetFences(v->dev, 1, &v->fence));
    return true;
}

/* The engine's opaque pass in Vulkan, then its copy of the scene colour into the output image
 * the plugin draws over; all three images released to the external (GL) side in GENERAL. */
static bool vk_scene_frame(vk *v)
{
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    VK_TRY(vkBeginCommandBuffer(v->cmd, &bi));
    VkClearValue clear[2] = {{.color = {{sky[0], sky[1], sky[2], sky[3]}}}, {.depthStencil = {1, 0}}};
    VkRenderPassBeginInfo rb = {.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO, .renderPass = v->pass,
                                .framebuffer = v->fb, .renderArea = {{0, 0}, {W, H}}, .clearValueCount = 2,
                                .pClearValues = clear};
    vkCmdBeginRenderPass(v->cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(v->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, v->pipe);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(v->cmd, 0, 1, &v->vbuf, &off);
    vkCmdDraw(v->cmd, 12, 1, 0, 0);
    vkCmdEndRenderPass(v->cmd);
    const uint32_t Q = VK_QUEUE_FAMILY_IGNORED;
    VkImageMemoryBarrier pre[2] = {
        image_barrier(v->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, Q, Q),
        image_barrier(v->out.image, VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, Q, Q)};
    vkCmdPipelineBarrier(v->cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 2, pre);
    VkImageCopy copy = {.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
                        .extent = {W, H, 1}};
    vkCmdCopyImage(v->cmd, v->color.image, VK_IMAGE_LAYOUT_GENERAL, v->out.image, VK_IMAGE_LAYOUT_GENERAL, 1, &copy);
    /* release to GL: a queue family ownership transfer to VK_QUEUE_FAMILY_EXTERNAL, so that
     * drivers that compress or cache images make them whole before another API reads them */
    const uint32_t X = VK_QUEUE_FAMILY_EXTERNAL;
    VkImageMemoryBarrier rel[3] = {
        image_barrier(v->color.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, 0,
                      VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, v->family, X),
        image_barrier(v->depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, 0,
                      VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, v->family, X),
        image_barrier(v->out.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, 0,
                      VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, v->family, X)};
    vkCmdPipelineBarrier(v->cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT
                                     | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, NULL, 0, NULL, 3, rel);
    return vk_submit_wait(v);
}

/* Vulkan reads the output image back after GL finished with it (acquired from the external
 * side), as the engine would composite or present it. */
static bool vk_read_output(vk *v, unsigned char *rgba)
{
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    VK_TRY(vkBeginCommandBuffer(v->cmd, &bi));
    VkImageMemoryBarrier acq = image_barrier(v->out.image, VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_ACCESS_TRANSFER_READ_BIT,
                                             VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, VK_QUEUE_FAMILY_EXTERNAL,
                                             v->family);
    vkCmdPipelineBarrier(v->cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &acq);
    VkBufferImageCopy bc = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, .imageExtent = {W, H, 1}};
    vkCmdCopyImageToBuffer(v->cmd, v->out.image, VK_IMAGE_LAYOUT_GENERAL, v->rbuf, 1, &bc);
    VkBufferMemoryBarrier host = {.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER, .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
                                  .dstAccessMask = VK_ACCESS_HOST_READ_BIT, .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                                  .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED, .buffer = v->rbuf, .size = VK_WHOLE_SIZE};
    vkCmdPipelineBarrier(v->cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, NULL, 1, &host, 0, NULL);
    if (!vk_submit_wait(v))
        return false;
    memcpy(rgba, v->rmap, (size_t)W * H * 4);
    return true;
}

/* ------------------------------------------------------------------------- the check */

typedef struct result {
    unsigned char rgba[W * H * 4];
    float raw[VFX_EFFECT_COUNT][W * H];
} result;

/* One path's frames: `scene` draws the engine's opaque pass into t's colour and depth and copies
 * the colour into t's output; then the plugin's update and render into t's output framebuffer. */
static bool run_frames(const vfx_plugin_api *api, vfx_context *ctx, game *g, const targets *t, bool (*scene)(void *),
                       void *scene_user, const char *name)
{
    vfx_frame_view fv = camera();
    fv.framebuffer = t->out_fbo, fv.color_texture = t->color, fv.depth_texture = t->depth;
    for (int frame = 0; frame < FRAMES; ++frame) {
        g->frame = (uint64_t)frame;
        if (!scene(scene_user))
            return false;
        if (api->update(ctx, frame / 60.0, 1.f / 60.f) != VFX_OK || api->render(ctx, &fv) != VFX_OK) {
            fprintf(stderr, "%s frame %d: %s\n", name, frame, api->last_error(ctx, NULL));
            return false;
        }
        glFinish(); /* GL's writes done before the engine (Vulkan) reads the output */
    }
    return true;
}

static bool read_raws(const vfx_plugin_api *api, vfx_context *ctx, result *r)
{
    for (int e = 0; e < VFX_EFFECT_COUNT; ++e)
        if ((api->effects_built & VFX_EFFECT_BIT(e)) && api->read_raw(ctx, (vfx_effect_kind)e, r->raw[e], W * H) != VFX_OK) {
            fprintf(stderr, "read_raw(%d): %s\n", e, api->last_error(ctx, NULL));
            return false;
        }
    return true;
}

static bool covered(int effect, float v)
{
    switch (effect) {
    case VFX_EFFECT_WATER: return v >= 0; /* ray distance, -1 = miss */
    case VFX_EFFECT_BEAMS: return v > 1e-3f; /* H */
    default: return v > 1e-3f; /* accumulated opacity */
    }
}

/* Each effect's coverage and the final image of the Vulkan path against the GL path. Both run
 * the same plugin on the same rasteriser (llvmpipe under lavapipe and GL), so a handful of edge
 * pixels is the most that may differ; a wrong import (layout, format, depth convention, rows
 * flipped, stale data) moves or hides whole regions. */
static int compare(const result *vkr, const result *glr, uint32_t effects)
{
    static const char *names[VFX_EFFECT_COUNT] = {"water", "beams", "volume"};
    int fail = 0;
    for (int e = 0; e < VFX_EFFECT_COUNT; ++e) {
        if (!(effects & VFX_EFFECT_BIT(e)))
            continue; /* not built into this plugin (-Dmetaballs/-Dbeams/-Dtetvol=false) */
        int cov_vk = 0, cov_gl = 0, differ = 0;
        for (int i = 0; i < W * H; ++i) {
            bool a = covered(e, vkr->raw[e][i]), b = covered(e, glr->raw[e][i]);
            cov_vk += a, cov_gl += b, differ += a != b;
        }
        /* tolerance: 1% of the covered pixels (at least 3) for the atomics' rounding in the
         * water's potential sums and rasteriser edge rules at the scene's triangle edges */
        int allowed = cov_gl / 100 > 3 ? cov_gl / 100 : 3;
        bool ok = cov_gl > 50 && differ <= allowed;
        printf("%-6s coverage: vulkan %d px, GL %d px, %d differ (allowed %d): %s\n", names[e], cov_vk, cov_gl, differ,
               allowed, ok ? "ok" : "MISMATCH");
        fail |= !ok;
    }
    double sum = 0;
    int maxd = 0, big = 0;
    for (int i = 0; i < W * H * 4; ++i) {
        if (i % 4 == 3)
            continue;
        int d = abs((int)vkr->rgba[i] - (int)glr->rgba[i]);
        sum += d, maxd = d > maxd ? d : maxd, big += d > 8;
    }
    double mean = sum / (W * H * 3.0);
    /* mean under 0.5/255 and at most 1% of the channels off by more than 8/255 */
    bool ok = mean < 0.5 && big <= W * H * 3 / 100;
    printf("image: mean |vulkan - GL| %.3f/255, max %d, %d channels > 8: %s\n", mean, maxd, big, ok ? "ok" : "MISMATCH");
    return fail | !ok;
}

/* The comparison's self-test: a comparison that never fails passes any import. The GL result
 * against itself must match, and against itself shifted `dx` pixels to the right (the left
 * columns filled with the first one's) must not: a shift of 4 moves every edge of the scene and
 * its effects by more than the 1% of covered pixels and the 1% of channels the tolerances allow. */
static int compare_self_test(const result *glr, uint32_t effects, int dx)
{
    static result sh;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int sx = x - dx < 0 ? 0 : x - dx;
            memcpy(&sh.rgba[4 * (y * W + x)], &glr->rgba[4 * (y * W + sx)], 4);
            for (int e = 0; e < VFX_EFFECT_COUNT; ++e)
                sh.raw[e][y * W + x] = glr->raw[e][y * W + sx];
        }
    printf("self-test: GL against itself\n");
    int same = compare(glr, glr, effects);
    printf("self-test: GL against itself shifted %d px (must mismatch)\n", dx);
    int shifted = compare(&sh, glr, effects);
    bool ok = same == 0 && shifted != 0;
    printf("self-test of the comparison: %s\n", ok ? "ok" : "FAILED (a shifted image passed, or an identical one failed)");
    return ok ? 0 : 1;
}

static void write_ppm(const char *prefix, const char *which, const unsigned char *rgba)
{
    char path[512];
    snprintf(path, sizeof path, "%s-%s.ppm", prefix, which);
    FILE *f = fopen(path, "wb");
    if (!f)
        return;
    fprintf(f, "P6 %d %d 255\n", W, H);
    for (int y = H - 1; y >= 0; --y) /* memory row 0 is the bottom row in GL's terms */
        for (int x = 0; x < W; ++x)
            fwrite(&rgba[4 * (y * W + x)], 1, 3, f);
    fclose(f);
}

static bool vk_scene_cb(void *user) { return vk_scene_frame(user); }
static bool gl_scene_cb(void *user) { gl_scene_draw(user); return true; }

static int run(vfx_plugin_api *api, vfx_context_desc *host, game *g, vk *v, gl_scene *gs, result *vkr, result *glr)
{
    vfx_context *cv = NULL, *cg = NULL;
    int rc = 1;
    if (api->create(host, &cv) != VFX_OK || api->create(host, &cg) != VFX_OK)
        goto out;
    if (!run_frames(api, cv, g, &v->t, vk_scene_cb, v, "vulkan") || !vk_read_output(v, vkr->rgba) || !read_raws(api, cv, vkr))
        goto out;
    if (!run_frames(api, cg, g, &gs->t, gl_scene_cb, gs, "GL") || !read_raws(api, cg, glr))
        goto out;
    glGetTextureImage(gs->t.out, 0, GL_RGBA, GL_UNSIGNED_BYTE, sizeof glr->rgba, glr->rgba);
    rc = compare(vkr, glr, api->effects_built);
    rc |= compare_self_test(glr, api->effects_built, 4);
out:
    api->destroy(cv);
    api->destroy(cg);
    return rc;
}

int main(int argc, char **argv)
{
    const char *ppm = argc > 2 && strcmp(argv[1], "--ppm") == 0 ? argv[2] : NULL;
    if (!make_context()) {
        fprintf(stderr, "no GL 4.5 context: skipping\n");
        return 77;
    }
    if (!epoxy_has_gl_extension("GL_EXT_memory_object_fd")) {
        fprintf(stderr, "GL (%s) has no GL_EXT_memory_object_fd\n", (const char *)glGetString(GL_RENDERER));
        return 1;
    }
    printf("GL: %s, GL_EXT_semaphore_fd %s\n", (const char *)glGetString(GL_RENDERER),
           epoxy_has_gl_extension("GL_EXT_semaphore_fd") ? "present (not needed: fences and glFinish here)"
                                                         : "absent: fences and glFinish");
    static game g;
    static vk v;
    static gl_scene gs;
    static result vkr, glr;
    setup(&g);
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &g, .gl_get_proc_address = on_proc,
                         .log = on_log, .particle_chunk_count = on_chunks, .particle_chunk = on_chunk, .beams = on_beams,
                         .volume_count = on_volumes, .volume = on_volume};
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    int rc = 1;
    if (!vk_create(&v, &g) || !gl_scene_create(&gs, &g)) {
        fprintf(stderr, "vulkan host: set-up failed\n");
    } else if (vfx_plugin_entry(VFX_ABI_VERSION, &host, &api) == VFX_OK) {
        rc = run(&api, &host, &g, &v, &gs, &vkr, &glr);
        if (ppm) {
            write_ppm(ppm, "vulkan", vkr.rgba);
            write_ppm(ppm, "gl", glr.rgba);
        }
    }
    gl_scene_destroy(&gs);
    vk_destroy(&v);
    printf("%d plugin errors, %d validation errors\n", g.errors, v.validation_errors);
    if (g.errors || v.validation_errors)
        rc = 1;
    return rc;
}
