/* Off-screen float rendering through OSMesa (gallium llvmpipe): the only file that includes OSMesa. */
#include "render/osmesa.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/threads.h"

/* design: gallium OSMesa (Mesa 22.3) renders into an internal resource of the format chosen by the
 * buffer type (GL_FLOAT gives R32G32B32A32_FLOAT) and copies it to the caller's buffer on glFinish,
 * so attributes keep full float precision without any multi-pass encoding. The fixed-function
 * pipeline clamps vertex colours to [0, 1] unless GL_CLAMP_VERTEX_COLOR is off (glClampColor,
 * GL 3.0 / ARB_color_buffer_float); fragment clamping is switched off too, for good measure. */

/* design: OpenGL clips triangles that leave the viewport, and llvmpipe's clipper makes new vertices
 * whose snapping bends the cut edges by up to half a subpixel, so a sample lying very near an edge
 * could fall on either side depending on where the tile boundary is. The viewport is therefore a
 * power-of-two square much larger than the buffer (the buffer bounds still limit rasterisation
 * exactly), so triangles reaching out of a tile by less than the margin are never clipped, and the
 * window -> clip -> window round trip is exact for coordinates on a 1/256-sample grid. */

typedef struct lit_state lit_state;

struct fs_osmesa {
    OSMesaContext ctx;
    int width, height;
    int viewport;  /* side of the square viewport (a power of two) */
    int margin;    /* viewport extends this many samples beyond the buffer on the left and bottom */
    float *buffer; /* width * height RGBA, rows bottom to top */
    lit_state *lit; /* the lit pass, once loaded */
};

/* Depth bits asked for; llvmpipe gives 24 (Z24), which resolves height differences of 2^-24 of the
 * drawn height range. */
static const int depth_bits = 32;

static int gl_check(const char *what)
{
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %s failed (GL error 0x%04x)", what, (unsigned)e);
        return -1;
    }
    return 0;
}

/* design: llvmpipe rasterises on a pool of threads it sizes when it creates its screen, at the
 * first context of the process, from LP_NUM_THREADS (else the processors); tiles are drawn whole by
 * one thread, so the image does not depend on the count. With a thread budget given (-j; base/
 * threads.h), LP_NUM_THREADS is set to it before that first context (the calling thread waits
 * while they draw). */
static void apply_raster_threads(void)
{
    static bool done;
    if (done || !fs_threads_given())
        return;
    done = true;
    char n[16];
    snprintf(n, sizeof n, "%d", fs_threads());
    setenv("LP_NUM_THREADS", n, 1);
}

fs_osmesa *fs_osmesa_create(int width, int height)
{
    apply_raster_threads();
    FS_ASSERT(width > 0 && height > 0);
    fs_osmesa *g = fs_calloc(1, sizeof *g);
    g->width = width;
    g->height = height;
    g->buffer = fs_malloc((size_t)width * (size_t)height * 4 * sizeof(float));
    g->ctx = OSMesaCreateContextExt(OSMESA_RGBA, depth_bits, 0, 0, NULL);
    if (!g->ctx) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot create a context");
        goto fail;
    }
    if (!OSMesaMakeCurrent(g->ctx, g->buffer, GL_FLOAT, width, height)) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot bind a %d x %d float colour buffer", width, height);
        goto fail;
    }
    GLint max_w = 0, max_h = 0, y_up = 0, depth = 0;
    OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_w);
    OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_h);
    if (width > max_w || height > max_h) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %d x %d exceeds the largest buffer (%d x %d)", width, height,
                 (int)max_w, (int)max_h);
        goto fail;
    }
    OSMesaGetIntegerv(OSMESA_Y_UP, &y_up);
    glGetIntegerv(GL_DEPTH_BITS, &depth);
    if (!y_up || depth < 16) {
        fs_error(FS_ERR_INTERNAL, "osmesa: unexpected buffer layout (y up %d, %d depth bits)", (int)y_up,
                 (int)depth);
        goto fail;
    }
    PFNGLCLAMPCOLORPROC clamp_color = (PFNGLCLAMPCOLORPROC)OSMesaGetProcAddress("glClampColor");
    if (!clamp_color) {
        fs_error(FS_ERR_INTERNAL, "osmesa: glClampColor is missing (OpenGL 3.0 needed)");
        goto fail;
    }
    clamp_color(GL_CLAMP_VERTEX_COLOR, GL_FALSE);
    clamp_color(GL_CLAMP_FRAGMENT_COLOR, GL_FALSE);
    if (gl_check("disabling colour clamping") != 0)
        goto fail;

    GLint dims[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
    g->viewport = 1;
    while (2 * g->viewport <= dims[0] && 2 * g->viewport <= dims[1])
        g->viewport *= 2;
    int side = width > height ? width : height;
    if (g->viewport < side) {
        fs_error(FS_ERR_INTERNAL, "osmesa: %d x %d exceeds the largest viewport (%d)", width, height,
                 g->viewport);
        goto fail;
    }
    g->margin = (g->viewport - side) / 2;
    glViewport(-g->margin, -g->margin, g->viewport, g->viewport);
    glDisable(GL_DITHER);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_LIGHTING);
    glShadeModel(GL_SMOOTH);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    if (gl_check("setting up the pipeline") != 0)
        goto fail;
    return g;

fail:
    fs_osmesa_destroy(g);
    return NULL;
}

void fs_osmesa_destroy(fs_osmesa *g)
{
    if (!g)
        return;
    fs_osmesa_lit_unload(g);
    if (g->ctx) {
        if (OSMesaGetCurrentContext() == g->ctx)
            OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
        OSMesaDestroyContext(g->ctx);
    }
    free(g->buffer);
    free(g);
}

int fs_osmesa_begin(fs_osmesa *g, const float clear[4], double height_lo, double height_hi)
{
    FS_ASSERT(height_hi > height_lo);
    /* Window x, y are buffer samples (the viewport's margin shifts them back); eye z is the height,
     * so near = -height_hi maps to depth 0 and the highest surface passes GL_LESS against everything
     * below it. */
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    double lo = -(double)g->margin, hi = (double)(g->viewport - g->margin);
    glOrtho(lo, hi, lo, hi, -height_hi, -height_lo);
    glMatrixMode(GL_MODELVIEW);
    glClearColor(clear[0], clear[1], clear[2], clear[3]);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    return gl_check("clearing");
}

int fs_osmesa_draw(fs_osmesa *g, const float *xyh, const float *attr, const uint32_t *tri, int32_t n_tris)
{
    (void)g;
    if (n_tris <= 0)
        return 0;
    glVertexPointer(3, GL_FLOAT, 0, xyh);
    glColorPointer(4, GL_FLOAT, 0, attr);
    glDrawElements(GL_TRIANGLES, 3 * n_tris, GL_UNSIGNED_INT, tri);
    return gl_check("drawing");
}

const float *fs_osmesa_finish(fs_osmesa *g)
{
    glFinish();
    if (gl_check("finishing") != 0)
        return NULL;
    return g->buffer;
}

/* ---- the lit pass ---- */

/* Samples per pixel of the multisampled target (llvmpipe offers 4). */
static const int lit_samples = 4;

enum { ATTR_POS, ATTR_NORMAL, ATTR_UV, ATTR_TINT, ATTR_TANGENT, ATTR_INDEX, N_BUFFERS };
#define N_ATTRS 5

struct lit_state {
    GLuint program, depth_program;
    GLuint vao;
    int n_meshes;
    GLuint *buffers;   /* N_BUFFERS per mesh */
    GLsizei *counts;   /* indices per mesh */
    GLuint texture, normal_texture;
    float normal_green_sign;
    GLuint shadow_tex, shadow_fbo;
    GLuint msaa_fbo, msaa_color, msaa_depth;
    fs_osmesa_scene scene;
};

static const char *const lit_vertex_source =
    "#version 330\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "layout(location = 3) in vec4 a_tint;\n"
    "layout(location = 4) in vec3 a_tu;\n"
    "layout(location = 5) in vec3 a_tv;\n"
    "uniform mat4 u_clip_from_world;\n"
    "out vec3 v_pos;\n"
    "out vec3 v_normal;\n"
    "out vec2 v_uv;\n"
    "out vec4 v_tint;\n"
    "out vec3 v_tu;\n"
    "out vec3 v_tv;\n"
    "void main() {\n"
    "    v_pos = a_pos;\n"
    "    v_normal = a_normal;\n"
    "    v_uv = a_uv;\n"
    "    v_tint = a_tint;\n"
    "    v_tu = a_tu;\n"
    "    v_tv = a_tv;\n"
    "    gl_Position = u_clip_from_world * vec4(a_pos, 1.0);\n"
    "}\n";

static const char *const lit_fragment_source =
    "#version 330\n"
    "in vec3 v_pos;\n"
    "in vec3 v_normal;\n"
    "in vec2 v_uv;\n"
    "in vec4 v_tint;\n"
    "in vec3 v_tu;\n"
    "in vec3 v_tv;\n"
    "uniform sampler2D u_color;\n"
    "uniform sampler2D u_normal_map;\n"
    "uniform float u_green_sign;\n"
    "uniform sampler2DShadow u_shadow;\n"
    "uniform mat4 u_shadow_from_world;\n"
    "uniform int u_use_shadow;\n"
    "uniform float u_shadow_texel, u_shadow_offset, u_specular, u_shininess;\n"
    "uniform vec3 u_eye, u_light_dir, u_light_rgb, u_sky_rgb, u_ground_rgb, u_up;\n"
    "out vec4 o_color;\n"
    "void main() {\n"
    "    vec3 n = normalize(v_normal);\n"
    "    vec3 view = normalize(u_eye - v_pos);\n"
    "    float facing = dot(n, view) < 0.0 ? -1.0 : 1.0;\n"
    "    if (v_tint.a > 0.0) {\n"
    "        vec3 m = texture(u_normal_map, v_uv).rgb * 2.0 - 1.0;\n"
    "        vec3 tu = normalize(v_tu), tv = normalize(v_tv), tn = normalize(cross(tu, tv));\n"
    "        vec3 mapped = normalize(tu * m.x + tv * (m.y * u_green_sign) + tn * m.z);\n"
    "        n = normalize(mix(n, mapped, v_tint.a));\n"
    "    }\n"
    "    n *= facing;\n"
    "    vec3 albedo = mix(v_tint.rgb, texture(u_color, v_uv).rgb, v_tint.a);\n"
    "    float lit = 1.0;\n"
    "    if (u_use_shadow != 0) {\n"
    "        vec4 s = u_shadow_from_world * vec4(v_pos + n * u_shadow_offset, 1.0);\n"
    "        vec3 t = s.xyz / s.w * 0.5 + 0.5;\n"
    "        lit = 0.0;\n"
    "        for (int j = -1; j <= 1; j++)\n"
    "            for (int i = -1; i <= 1; i++)\n"
    "                lit += texture(u_shadow, vec3(t.xy + vec2(i, j) * u_shadow_texel, t.z));\n"
    "        lit /= 9.0;\n"
    "    }\n"
    "    float diffuse = max(dot(n, u_light_dir), 0.0);\n"
    "    vec3 h = normalize(u_light_dir + view);\n"
    "    float spec = diffuse > 0.0 ? u_specular * pow(max(dot(n, h), 0.0), u_shininess) : 0.0;\n"
    "    vec3 ambient = mix(u_ground_rgb, u_sky_rgb, 0.5 + 0.5 * dot(n, u_up));\n"
    "    vec3 c = albedo * (ambient + u_light_rgb * diffuse * lit) + u_light_rgb * spec * lit;\n"
    "    o_color = vec4(c, 1.0);\n"
    "}\n";

static const char *const depth_vertex_source =
    "#version 330\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "uniform mat4 u_clip_from_world;\n"
    "void main() { gl_Position = u_clip_from_world * vec4(a_pos, 1.0); }\n";

static const char *const depth_fragment_source =
    "#version 330\n"
    "void main() { }\n";

static GLuint compile(GLenum type, const char *source, const char *what)
{
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, 1, &source, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        fs_error(FS_ERR_INTERNAL, "osmesa: the %s shader does not compile: %s", what, log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

static GLuint link_program(const char *vs_source, const char *fs_source, const char *what)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_source, what);
    GLuint fs = vs ? compile(GL_FRAGMENT_SHADER, fs_source, what) : 0;
    if (!fs) {
        if (vs)
            glDeleteShader(vs);
        return 0;
    }
    GLuint prog = glCreateProgram();
    glAttachShader(prog, vs);
    glAttachShader(prog, fs);
    glLinkProgram(prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetProgramInfoLog(prog, sizeof log, NULL, log);
        fs_error(FS_ERR_INTERNAL, "osmesa: the %s program does not link: %s", what, log);
        glDeleteProgram(prog);
        return 0;
    }
    return prog;
}

static void set_vec3(GLuint prog, const char *name, const float *v)
{
    glUniform3f(glGetUniformLocation(prog, name), v[0], v[1], v[2]);
}

/* Puts the raster pass's state back: no program, buffers, framebuffer or vertex array bound, and
 * its viewport. */
static void restore_raster_state(fs_osmesa *g)
{
    glUseProgram(0);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_MULTISAMPLE);
    glViewport(-g->margin, -g->margin, g->viewport, g->viewport);
}

static void draw_meshes(const lit_state *L)
{
    glBindVertexArray(L->vao);
    for (int k = 0; k < L->n_meshes; k++) {
        if (L->counts[k] == 0)
            continue;
        const GLuint *b = L->buffers + N_BUFFERS * k;
        static const GLint sizes[N_ATTRS] = {3, 3, 2, 4, 3};
        for (int a = 0; a < N_ATTRS; a++) {
            glBindBuffer(GL_ARRAY_BUFFER, b[a]);
            glVertexAttribPointer((GLuint)a, sizes[a], GL_FLOAT, GL_FALSE, a == ATTR_TANGENT ? 6 * sizeof(float) : 0,
                                  NULL);
            glEnableVertexAttribArray((GLuint)a);
        }
        /* the v direction follows the u direction in each tangent record */
        glVertexAttribPointer(N_ATTRS, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (const void *)(3 * sizeof(float)));
        glEnableVertexAttribArray(N_ATTRS);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b[ATTR_INDEX]);
        glDrawElements(GL_TRIANGLES, L->counts[k], GL_UNSIGNED_INT, NULL);
    }
}

/* Uploads an RGB image with rows bottom to top, so that texture v goes up the image, mipmapped. */
static GLuint upload_rgb(int width, int height, const uint8_t *rgb, GLenum internal, bool wrap_u, bool wrap_v)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    size_t row = 3 * (size_t)width;
    uint8_t *flipped = fs_malloc(row * (size_t)height);
    for (int j = 0; j < height; j++)
        memcpy(flipped + row * (size_t)j, rgb + row * (size_t)(height - 1 - j), row);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, (GLint)internal, width, height, 0, GL_RGB, GL_UNSIGNED_BYTE, flipped);
    free(flipped);
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap_u ? GL_REPEAT : GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap_v ? GL_REPEAT : GL_CLAMP_TO_EDGE);
    glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, 8.0f);
    return t;
}

static int make_targets(fs_osmesa *g, lit_state *L)
{
    glGenFramebuffers(1, &L->msaa_fbo);
    glGenRenderbuffers(1, &L->msaa_color);
    glGenRenderbuffers(1, &L->msaa_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, L->msaa_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, lit_samples, GL_RGBA32F, g->width, g->height);
    glBindRenderbuffer(GL_RENDERBUFFER, L->msaa_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, lit_samples, GL_DEPTH_COMPONENT24, g->width, g->height);
    glBindFramebuffer(GL_FRAMEBUFFER, L->msaa_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, L->msaa_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, L->msaa_depth);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot make a %d x %d multisampled float target (status 0x%04x)", g->width,
                 g->height, (unsigned)status);
        return -1;
    }
    int size = L->scene.shadow_size;
    if (size <= 0)
        return 0;
    glGenTextures(1, &L->shadow_tex);
    glBindTexture(GL_TEXTURE_2D, L->shadow_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    static const float far_border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, far_border);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &L->shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, L->shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, L->shadow_tex, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        fs_error(FS_ERR_INTERNAL, "osmesa: cannot make a %d x %d shadow map (status 0x%04x)", size, size,
                 (unsigned)status);
        return -1;
    }
    return 0;
}

/* Renders the depth of the scene seen from the light into the shadow map; slope-scaled polygon
 * offset keeps lit surfaces from shadowing themselves. */
static void render_shadow(lit_state *L)
{
    glBindFramebuffer(GL_FRAMEBUFFER, L->shadow_fbo);
    glViewport(0, 0, L->scene.shadow_size, L->scene.shadow_size);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    glUseProgram(L->depth_program);
    glUniformMatrix4fv(glGetUniformLocation(L->depth_program, "u_clip_from_world"), 1, GL_FALSE,
                       L->scene.shadow_from_world);
    draw_meshes(L);
    glDisable(GL_POLYGON_OFFSET_FILL);
}

int fs_osmesa_lit_load(fs_osmesa *g, const fs_osmesa_scene *s, const fs_osmesa_mesh *meshes, int n_meshes,
                       const fs_osmesa_texture *tex)
{
    fs_osmesa_lit_unload(g);
    lit_state *L = fs_calloc(1, sizeof *L);
    g->lit = L;
    L->scene = *s;
    L->program = link_program(lit_vertex_source, lit_fragment_source, "lit");
    L->depth_program = L->program ? link_program(depth_vertex_source, depth_fragment_source, "shadow") : 0;
    if (!L->depth_program || gl_check("compiling the lit pass") != 0)
        goto fail;
    glGenVertexArrays(1, &L->vao);
    L->n_meshes = n_meshes;
    L->buffers = fs_calloc((size_t)N_BUFFERS * (size_t)(n_meshes > 0 ? n_meshes : 1), sizeof *L->buffers);
    L->counts = fs_calloc((size_t)(n_meshes > 0 ? n_meshes : 1), sizeof *L->counts);
    for (int k = 0; k < n_meshes; k++) {
        const fs_osmesa_mesh *m = meshes + k;
        GLuint *b = L->buffers + N_BUFFERS * k;
        glGenBuffers(N_BUFFERS, b);
        const float *data[N_ATTRS] = {m->pos, m->normal, m->uv, m->tint, m->tangent};
        static const size_t sizes[N_ATTRS] = {3, 3, 2, 4, 6};
        for (int a = 0; a < N_ATTRS; a++) {
            glBindBuffer(GL_ARRAY_BUFFER, b[a]);
            glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizes[a] * (size_t)m->n_verts * sizeof(float)), data[a],
                         GL_STATIC_DRAW);
        }
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b[ATTR_INDEX]);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(3 * (size_t)m->n_tris * sizeof(uint32_t)), m->tri,
                     GL_STATIC_DRAW);
        L->counts[k] = 3 * (GLsizei)m->n_tris;
    }
    L->texture = upload_rgb(tex->width, tex->height, tex->rgb, GL_SRGB8, tex->wrap_u, tex->wrap_v);
    L->normal_texture =
        upload_rgb(tex->normal_width, tex->normal_height, tex->normal, GL_RGB8, tex->wrap_u, tex->wrap_v);
    L->normal_green_sign = tex->normal_green_sign;
    if (gl_check("uploading the lit scene") != 0 || make_targets(g, L) != 0)
        goto fail;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    if (L->scene.shadow_size > 0)
        render_shadow(L);
    int rc = gl_check("rendering the shadow map");
    restore_raster_state(g);
    if (rc != 0)
        goto fail;
    return 0;

fail:
    restore_raster_state(g);
    fs_osmesa_lit_unload(g);
    return -1;
}

int fs_osmesa_lit_draw(fs_osmesa *g, const float clip_from_world[16])
{
    lit_state *L = g->lit;
    FS_ASSERT(L);
    const fs_osmesa_scene *s = &L->scene;
    glBindFramebuffer(GL_FRAMEBUFFER, L->msaa_fbo);
    glViewport(0, 0, g->width, g->height);
    glEnable(GL_MULTISAMPLE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    GLuint p = L->program;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_clip_from_world"), 1, GL_FALSE, clip_from_world);
    glUniformMatrix4fv(glGetUniformLocation(p, "u_shadow_from_world"), 1, GL_FALSE, s->shadow_from_world);
    glUniform1i(glGetUniformLocation(p, "u_use_shadow"), s->shadow_size > 0);
    glUniform1f(glGetUniformLocation(p, "u_shadow_texel"), s->shadow_size > 0 ? 1.0f / (float)s->shadow_size : 0.0f);
    glUniform1f(glGetUniformLocation(p, "u_shadow_offset"), s->shadow_offset);
    glUniform1f(glGetUniformLocation(p, "u_specular"), s->specular);
    glUniform1f(glGetUniformLocation(p, "u_shininess"), s->shininess);
    set_vec3(p, "u_eye", s->eye);
    set_vec3(p, "u_light_dir", s->light_dir);
    set_vec3(p, "u_light_rgb", s->light_rgb);
    set_vec3(p, "u_sky_rgb", s->sky_rgb);
    set_vec3(p, "u_ground_rgb", s->ground_rgb);
    set_vec3(p, "u_up", s->up);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, L->texture);
    glUniform1i(glGetUniformLocation(p, "u_color"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, L->shadow_tex);
    glUniform1i(glGetUniformLocation(p, "u_shadow"), 1);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, L->normal_texture);
    glUniform1i(glGetUniformLocation(p, "u_normal_map"), 2);
    glUniform1f(glGetUniformLocation(p, "u_green_sign"), L->normal_green_sign);
    draw_meshes(L);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, L->msaa_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, g->width, g->height, 0, 0, g->width, g->height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    int rc = gl_check("drawing the lit scene");
    restore_raster_state(g);
    return rc;
}

void fs_osmesa_lit_unload(fs_osmesa *g)
{
    lit_state *L = g ? g->lit : NULL;
    if (!L)
        return;
    if (L->buffers) {
        for (int k = 0; k < L->n_meshes; k++)
            glDeleteBuffers(N_BUFFERS, L->buffers + N_BUFFERS * k);
    }
    if (L->vao)
        glDeleteVertexArrays(1, &L->vao);
    if (L->texture)
        glDeleteTextures(1, &L->texture);
    if (L->normal_texture)
        glDeleteTextures(1, &L->normal_texture);
    if (L->shadow_tex)
        glDeleteTextures(1, &L->shadow_tex);
    if (L->shadow_fbo)
        glDeleteFramebuffers(1, &L->shadow_fbo);
    if (L->msaa_fbo)
        glDeleteFramebuffers(1, &L->msaa_fbo);
    if (L->msaa_color)
        glDeleteRenderbuffers(1, &L->msaa_color);
    if (L->msaa_depth)
        glDeleteRenderbuffers(1, &L->msaa_depth);
    if (L->program)
        glDeleteProgram(L->program);
    if (L->depth_program)
        glDeleteProgram(L->depth_program);
    free(L->buffers);
    free(L->counts);
    free(L);
    g->lit = NULL;
}
