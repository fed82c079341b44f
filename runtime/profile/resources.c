/* resources.c — /proc/self/statm and glIs* scans. */
#include "profile/resources.h"

#include <epoxy/gl.h>
#include <stdio.h>
#include <unistd.h>

uint64_t rt_resident_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return 0;
    unsigned long size = 0, resident = 0;
    int n = fscanf(f, "%lu %lu", &size, &resident);
    fclose(f);
    long page = sysconf(_SC_PAGESIZE);
    return n == 2 && page > 0 ? (uint64_t)resident * (uint64_t)page : 0;
}

rt_gl_object_counts rt_gl_count_objects(uint32_t max_name)
{
    rt_gl_object_counts c = {0};
    for (GLuint i = 1; i <= max_name; ++i) {
        c.buffers += glIsBuffer(i) == GL_TRUE;
        c.textures += glIsTexture(i) == GL_TRUE;
        c.framebuffers += glIsFramebuffer(i) == GL_TRUE;
        c.vertex_arrays += glIsVertexArray(i) == GL_TRUE;
        c.programs += glIsProgram(i) == GL_TRUE;
        c.shaders += glIsShader(i) == GL_TRUE;
        c.queries += glIsQuery(i) == GL_TRUE;
    }
    c.total = c.buffers + c.textures + c.framebuffers + c.vertex_arrays + c.programs + c.shaders + c.queries;
    return c;
}
