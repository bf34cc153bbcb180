/* The lit perspective 3-D preview of a result (NAME_preview.png): a slab, a trunk segment or a globe. */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/vec.h"
#include "render/osmesa.h"

/* design: the preview draws the render mesh lifted into 3-D (render/lift.c, heights times
 * height_scale), which is exactly the surface the height and normal maps were rasterised from:
 * displacing a grid by the height map instead would blur every crack wall into a ramp one texel
 * wide. The basecolor map is its texture and the normal map its shading normal (it carries the
 * smooth bevels the mesh draws as fans of slivers); walls the lift added take the palette's crack
 * colour and their own normals, except low ones, mere seams between surfaces a model drew at
 * slightly different heights, which continue the surface around them.
 * Around it, a plane becomes a slab (its border profile extruded down to a base), a cylinder a
 * trunk segment (its ends closed by the bark's cross-section and end grain with growth rings),
 * a sphere a globe. The camera looks down at a fixed angle from the side away from the texture
 * seam and is moved back until the object fills the frame; the key light comes from the upper
 * left and casts shadows (osmesa.h), so cracks read as cuts. The linear result is composited over
 * a dark gradient, tone mapped and encoded as sRGB. All of it depends only on the mesh and the
 * parameters: the same mesh on the same machine gives the same image. */

/* Largest side of one rendered tile (the multisampled target holds 4 samples of 16 bytes per pixel). */
#define TILE_PIXELS 1024
#define SHADOW_SIZE 2048

/* Vertical field of view, and how much of the frame the object may fill. */
static const double fov_y_degrees = 30.0;
static const double frame_fill = 0.86;

typedef struct {
    float *pos, *normal, *uv, *tint, *tangent;
    uint32_t *tri;
    int32_t n_verts, n_tris, cap_verts, cap_tris;
} scene_mesh;

static const double no_tangent[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};

static int32_t mesh_vertex(scene_mesh *m, const double *p, const double *n, double u, double v, const float *tint,
                           const double *tangent)
{
    if (FS_ARRAY_GROW(m->cap_verts, m->n_verts + 1, 1024)) {
        FS_ARRAY_RESIZE(m->pos, 3 * (size_t)m->cap_verts);
        FS_ARRAY_RESIZE(m->normal, 3 * (size_t)m->cap_verts);
        FS_ARRAY_RESIZE(m->uv, 2 * (size_t)m->cap_verts);
        FS_ARRAY_RESIZE(m->tint, 4 * (size_t)m->cap_verts);
        FS_ARRAY_RESIZE(m->tangent, 6 * (size_t)m->cap_verts);
    }
    int32_t i = m->n_verts++;
    for (int q = 0; q < 3; q++) {
        m->pos[3 * i + q] = (float)p[q];
        m->normal[3 * i + q] = (float)n[q];
    }
    m->uv[2 * i] = (float)u;
    m->uv[2 * i + 1] = (float)v;
    memcpy(m->tint + 4 * (size_t)i, tint, 4 * sizeof *tint);
    for (int q = 0; q < 6; q++)
        m->tangent[6 * (size_t)i + q] = (float)tangent[q];
    return i;
}

static void mesh_tri(scene_mesh *m, int32_t a, int32_t b, int32_t c)
{
    if (FS_ARRAY_GROW(m->cap_tris, m->n_tris + 1, 1024))
        FS_ARRAY_RESIZE(m->tri, 3 * (size_t)m->cap_tris);
    m->tri[3 * m->n_tris] = (uint32_t)a;
    m->tri[3 * m->n_tris + 1] = (uint32_t)b;
    m->tri[3 * m->n_tris + 2] = (uint32_t)c;
    m->n_tris++;
}

/* A flat quad a, b, c, d with normal n. */
static void mesh_quad(scene_mesh *m, const double *a, const double *b, const double *c, const double *d,
                      const double *n, const float *tint)
{
    int32_t i = mesh_vertex(m, a, n, 0.0, 0.0, tint, no_tangent), j = mesh_vertex(m, b, n, 0.0, 0.0, tint, no_tangent);
    int32_t k = mesh_vertex(m, c, n, 0.0, 0.0, tint, no_tangent), l = mesh_vertex(m, d, n, 0.0, 0.0, tint, no_tangent);
    mesh_tri(m, i, j, k);
    mesh_tri(m, i, k, l);
}

static void mesh_free(scene_mesh *m)
{
    free(m->pos);
    free(m->normal);
    free(m->uv);
    free(m->tint);
    free(m->tangent);
    free(m->tri);
}

static void normalize3(double *v)
{
    double n = fs_norm3(v);
    if (n > 0.0)
        for (int q = 0; q < 3; q++)
            v[q] /= n;
}

/* Unit directions of increasing u and v on the domain at texture point (u, v): the frame of the
 * normal map. */
static void texture_frame(const fs_domain *d, double u, double v, double *frame)
{
    memset(frame, 0, 6 * sizeof *frame);
    double lon = 2.0 * FS_PI * u, lat = FS_PI * v - 0.5 * FS_PI;
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH:
        frame[0] = 1.0;
        frame[4] = 1.0;
        return;
    case FS_DOMAIN_CYLINDER:
        frame[0] = -sin(lon);
        frame[1] = cos(lon);
        frame[5] = 1.0;
        return;
    case FS_DOMAIN_SPHERE:
        frame[0] = -sin(lon);
        frame[1] = cos(lon);
        frame[3] = -sin(lat) * cos(lon);
        frame[4] = -sin(lat) * sin(lon);
        frame[5] = cos(lat);
        return;
    }
}

/* Height of a world point above the domain's surface. */
static double height_above(const fs_domain *d, const double *p)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH: return p[2];
    case FS_DOMAIN_CYLINDER: return hypot(p[0], p[1]) - d->radius;
    case FS_DOMAIN_SPHERE: return fs_norm3(p) - d->radius;
    }
    return 0.0;
}

/* Walls lower than this fraction of the layer's relief are seams between surfaces a model drew at
 * slightly different heights, not crack walls: they are textured like their surroundings. */
static const double low_wall = 0.1;

/* The lifted layer: textured and normal-mapped, with the lift's walls in the crack colour. Wall
 * triangles get vertices of their own, coloured by their height. */
static void add_layer(scene_mesh *m, const fs_lifted_mesh *l, const fs_domain *d, const fs_render_params *p,
                      double relief)
{
    int32_t *vert;
    uint32_t *tri;
    int32_t n = fs_lifted_mesh_vertices(l, &vert, &tri);
    const float top[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    const float side[4] = {p->color_crack[0], p->color_crack[1], p->color_crack[2], 0.0f};
    int32_t *index = fs_malloc(((size_t)n + 1) * sizeof *index);
    for (int32_t i = 0; i < n; i++)
        index[i] = -1;
    for (int32_t t = 0; t < l->n_tris; t++) {
        double lo = INFINITY, hi = -INFINITY;
        if (l->wall[t])
            for (int k = 0; k < 3; k++) {
                double h = height_above(d, l->pos + 3 * (size_t)l->corner[9 * (size_t)t + 3 * k]);
                lo = fmin(lo, h);
                hi = fmax(hi, h);
            }
        bool crack_wall = l->wall[t] && hi - lo >= low_wall * relief;
        int32_t v[3];
        for (int k = 0; k < 3; k++) {
            uint32_t i = tri[3 * t + k];
            if (!l->wall[t] && index[i] >= 0) {
                v[k] = index[i];
                continue;
            }
            const int32_t *c = vert + 3 * (size_t)i;
            double pos[3], nrm[3];
            for (int q = 0; q < 3; q++) {
                pos[q] = l->pos[3 * (size_t)c[0] + q];
                nrm[q] = l->normal[3 * (size_t)c[2] + q];
            }
            double u = l->uv[2 * (size_t)c[1]], w = l->uv[2 * (size_t)c[1] + 1], frame[6];
            texture_frame(d, u, w, frame);
            v[k] = mesh_vertex(m, pos, nrm, u, w, crack_wall ? side : top, frame);
            if (!l->wall[t])
                index[i] = v[k];
        }
        mesh_tri(m, v[0], v[1], v[2]);
    }
    free(index);
    free(vert);
    free(tri);
}

/* Plane: the border profile extruded down to z = -thickness, and the base. */
static void add_slab(scene_mesh *m, const fs_lifted_mesh *l, const int32_t *edges, int32_t n_edges, const fs_domain *d,
                     double thickness, const float *tint)
{
    for (int32_t e = 0; e < n_edges; e++) {
        const double *a = l->pos + 3 * (size_t)edges[2 * e], *b = l->pos + 3 * (size_t)edges[2 * e + 1];
        double a0[3] = {a[0], a[1], -thickness}, b0[3] = {b[0], b[1], -thickness};
        double n[3] = {b[1] - a[1], a[0] - b[0], 0.0};
        normalize3(n);
        mesh_quad(m, a, b, b0, a0, n, tint);
    }
    double c[4][3] = {{0.0, 0.0, -thickness}, {d->width, 0.0, -thickness}, {d->width, d->height, -thickness},
                      {0.0, d->height, -thickness}};
    double down[3] = {0.0, 0.0, -1.0};
    mesh_quad(m, c[0], c[3], c[2], c[1], down, tint);
}

/* Cylinder: each end closed by the bark's cross-section (from the surface down to the radius)
 * and end grain, a disc of growth rings. */
static void add_trunk_ends(scene_mesh *m, const fs_lifted_mesh *l, const int32_t *edges, int32_t n_edges,
                           const fs_domain *d, const float *bark)
{
    const int rings = 16;
    const double wood[3] = {0.34, 0.21, 0.10};
    for (int32_t e = 0; e < n_edges; e++) {
        const double *a = l->pos + 3 * (size_t)edges[2 * e], *b = l->pos + 3 * (size_t)edges[2 * e + 1];
        double z = a[2], n[3] = {0.0, 0.0, z > 0.5 * d->height ? 1.0 : -1.0};
        double ra = hypot(a[0], a[1]), rb = hypot(b[0], b[1]);
        if (!(ra > 0.0 && rb > 0.0))
            continue;
        double ua[2] = {a[0] / ra, a[1] / ra}, ub[2] = {b[0] / rb, b[1] / rb};
        double a_in[3] = {ua[0] * d->radius, ua[1] * d->radius, z}, b_in[3] = {ub[0] * d->radius, ub[1] * d->radius, z};
        mesh_quad(m, a, b, b_in, a_in, n, bark);
        for (int k = 0; k < rings; k++) {
            /* rings grow wider towards the bark; early and late wood alternate */
            double r0 = d->radius * sqrt((double)(rings - k) / rings);
            double r1 = d->radius * sqrt((double)(rings - k - 1) / rings);
            double shade = (k % 2 ? 0.82 : 1.0) * (1.0 + 0.06 * sin(2.4 * k));
            float t[4] = {(float)(wood[0] * shade), (float)(wood[1] * shade), (float)(wood[2] * shade), 0.0f};
            double p0[3] = {ua[0] * r0, ua[1] * r0, z}, p1[3] = {ub[0] * r0, ub[1] * r0, z};
            double q0[3] = {ua[0] * r1, ua[1] * r1, z}, q1[3] = {ub[0] * r1, ub[1] * r1, z};
            mesh_quad(m, p0, p1, q1, q0, n, t);
        }
    }
}

/* ---- camera ---- */

typedef struct {
    double up[3];      /* world up */
    double dir[3];     /* viewing direction */
    double right[3], cam_up[3];
    double target[3], distance;
    double tan_y, tan_x;
    double near, far;
} camera;

static void camera_basis(camera *c)
{
    fs_cross3(c->right, c->dir, c->up);
    normalize3(c->right);
    fs_cross3(c->cam_up, c->right, c->dir);
}

/* Moves the camera back along its direction and re-aims it until the points fill frame_fill of
 * the frame, centred. */
static void camera_fit(camera *c, const scene_mesh *const *meshes, int n_meshes, double radius)
{
    c->distance = radius / sin(atan(c->tan_y));
    for (int iter = 0; iter < 8; iter++) {
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (int k = 0; k < n_meshes; k++)
            for (int32_t i = 0; i < meshes[k]->n_verts; i++) {
                const float *p = meshes[k]->pos + 3 * (size_t)i;
                double q[3] = {p[0] - c->target[0], p[1] - c->target[1], p[2] - c->target[2]};
                double depth = c->distance + fs_dot3(q, c->dir);
                if (depth < 1e-3 * c->distance)
                    depth = 1e-3 * c->distance;
                double x = fs_dot3(q, c->right) / (depth * c->tan_x), y = fs_dot3(q, c->cam_up) / (depth * c->tan_y);
                lo[0] = fmin(lo[0], x);
                hi[0] = fmax(hi[0], x);
                lo[1] = fmin(lo[1], y);
                hi[1] = fmax(hi[1], y);
            }
        double sx = 0.5 * (lo[0] + hi[0]) * c->distance * c->tan_x, sy = 0.5 * (lo[1] + hi[1]) * c->distance * c->tan_y;
        for (int q = 0; q < 3; q++)
            c->target[q] += sx * c->right[q] + sy * c->cam_up[q];
        double need = fmax((hi[0] - lo[0]) / (2.0 * frame_fill), (hi[1] - lo[1]) / (2.0 * frame_fill));
        c->distance *= need;
    }
    c->near = fmax(c->distance - 1.5 * radius, 1e-3 * c->distance);
    c->far = c->distance + 1.5 * radius;
}

/* Column-major clip_from_world of the camera, with the tile's window [x0, x1] x [y0, y1] of NDC
 * stretched over the whole target. */
static void camera_matrix(const camera *c, double x0, double x1, double y0, double y1, float *out)
{
    double eye[3];
    for (int q = 0; q < 3; q++)
        eye[q] = c->target[q] - c->distance * c->dir[q];
    /* view rows: right, cam_up, -dir */
    double view[3][4];
    for (int q = 0; q < 3; q++) {
        view[0][q] = c->right[q];
        view[1][q] = c->cam_up[q];
        view[2][q] = -c->dir[q];
    }
    for (int r = 0; r < 3; r++)
        view[r][3] = -(view[r][0] * eye[0] + view[r][1] * eye[1] + view[r][2] * eye[2]);
    double sx = 2.0 / (x1 - x0), sy = 2.0 / (y1 - y0), cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    double n = c->near, f = c->far;
    /* perspective rows applied to view coordinates (x, y, z, 1), then the tile window */
    double proj[4][4] = {{sx / c->tan_x, 0.0, -sx * cx, 0.0},
                         {0.0, sy / c->tan_y, -sy * cy, 0.0},
                         {0.0, 0.0, -(f + n) / (f - n), -2.0 * f * n / (f - n)},
                         {0.0, 0.0, -1.0, 0.0}};
    /* the window shift multiplies clip w, which is -z: x' = sx x - sx cx w = sx x + sx cx z */
    proj[0][2] = sx * cx;
    proj[1][2] = sy * cy;
    for (int r = 0; r < 4; r++)
        for (int col = 0; col < 4; col++) {
            double v = 0.0;
            for (int k = 0; k < 3; k++)
                v += proj[r][k] * view[k][col];
            if (col == 3)
                v += proj[r][3];
            out[col * 4 + r] = (float)v;
        }
}

/* Column-major orthographic view from the light along -dir, covering the sphere (centre, radius). */
static void light_matrix(const double *dir, const double *centre, double radius, float *out)
{
    double x[3], y[3], z[3] = {dir[0], dir[1], dir[2]};
    double any[3] = {fabs(z[0]) < 0.9 ? 1.0 : 0.0, fabs(z[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    fs_cross3(x, any, z);
    normalize3(x);
    fs_cross3(y, z, x);
    const double *rows[3] = {x, y, z};
    double sign[3] = {1.0, 1.0, -1.0};
    for (int r = 0; r < 3; r++) {
        for (int q = 0; q < 3; q++)
            out[q * 4 + r] = (float)(sign[r] * rows[r][q] / radius);
        out[12 + r] = (float)(-sign[r] * fs_dot3(rows[r], centre) / radius);
    }
    out[3] = out[7] = out[11] = 0.0f;
    out[15] = 1.0f;
}

/* ---- tone mapping ---- */

static double tone_map(double x)
{
    /* a filmic curve (Narkowicz's fit of ACES), then sRGB encoding */
    x = x < 0.0 ? 0.0 : x;
    double y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    y = y > 1.0 ? 1.0 : y;
    return y <= 0.0031308 ? 12.92 * y : 1.055 * pow(y, 1.0 / 2.4) - 0.055;
}

static uint8_t to_byte(double x) { return (uint8_t)floor((x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x)) * 255.0 + 0.5); }

/* The backdrop at pixel (i, j): a dark slate gradient, lighter at the top and the middle. */
static void backdrop(int i, int j, int w, int h, double *rgb)
{
    double t = (double)j / (h > 1 ? h - 1 : 1), x = ((double)i / (w > 1 ? w - 1 : 1) - 0.5) * 2.0;
    double glow = exp(-1.5 * x * x);
    static const double top[3] = {0.070, 0.078, 0.092}, bottom[3] = {0.016, 0.018, 0.022};
    for (int q = 0; q < 3; q++)
        rgb[q] = (top[q] + (bottom[q] - top[q]) * t) * (0.75 + 0.25 * glow);
}

int fs_render_preview(const fs_surface *rm, const fs_domain *dom, const fs_render_params *p, const fs_maps *maps,
                      fs_image *out)
{
    memset(out, 0, sizeof *out);
    const int W = p->preview_width, H = p->preview_height;
    if (W < 16 || H < 16 || W > 16384 || H > 16384) {
        fs_error(FS_ERR_DATA, "preview: size %dx%d is outside 16..16384", W, H);
        return -1;
    }
    if (maps->basecolor.channels != 3 || maps->basecolor.type != FS_PIX_U8 || maps->normal.channels != 3 ||
        maps->normal.type != FS_PIX_U8) {
        fs_error(FS_ERR_INTERNAL, "preview: the basecolor and normal maps are not 8-bit RGB");
        return -1;
    }
    fs_domain d = *dom;
    fs_domain_normalize(&d);
    fs_lifted_mesh l;
    if (fs_render_lift(rm, &d, p->height_scale, &l) < 0)
        return -1;
    int32_t *edges = NULL, n_bad = 0;
    int32_t n_edges = fs_lifted_mesh_boundary(&l, &edges, &n_bad);
    if (n_bad > 0)
        fs_debug("preview: %d edges of the lifted mesh have more than two triangles", (int)n_bad);

    scene_mesh layer = {0}, body = {0};
    double h_max = 0.0;
    for (int32_t i = 0; i < rm->n_verts; i++)
        h_max = fmax(h_max, rm->height[i] * p->height_scale);
    add_layer(&layer, &l, &d, p, h_max);
    float body_tint[4], bark_tint[4] = {p->color_crack[0], p->color_crack[1], p->color_crack[2], 0.0f};
    for (int q = 0; q < 3; q++)
        body_tint[q] = 0.5f * (p->color_material[q] + p->color_crack[q]);
    body_tint[3] = 0.0f;

    camera cam;
    memset(&cam, 0, sizeof cam);
    double el = 0.0, az = 0.0, forward[3] = {0.0, 0.0, 0.0};
    switch (d.type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH: /* the texture's layout, flat */
        add_slab(&body, &l, edges, n_edges, &d, fmax(2.0 * h_max, 0.04 * fmin(d.width, d.height)), body_tint);
        cam.up[2] = 1.0;
        forward[1] = 1.0;
        el = 40.0;
        az = 25.0;
        break;
    case FS_DOMAIN_CYLINDER:
        add_trunk_ends(&body, &l, edges, n_edges, &d, bark_tint);
        forward[0] = 1.0; /* the seam (u = 0) faces away from the camera */
        if (d.height > 2.0 * d.radius) {
            cam.up[1] = 1.0; /* lying: the axis runs across the frame, one end towards the viewer */
            el = 22.0;
            az = 28.0;
        } else {
            cam.up[2] = 1.0;
            el = 20.0;
            az = 20.0;
        }
        break;
    case FS_DOMAIN_SPHERE:
        cam.up[2] = 1.0;
        forward[0] = 1.0;
        el = 18.0;
        az = 0.0;
        break;
    }
    double side[3];
    fs_cross3(side, forward, cam.up);
    double ce = cos(el * FS_PI / 180.0), se = sin(el * FS_PI / 180.0);
    double ca = cos(az * FS_PI / 180.0), sa = sin(az * FS_PI / 180.0);
    for (int q = 0; q < 3; q++)
        cam.dir[q] = ce * (ca * forward[q] + sa * side[q]) - se * cam.up[q];
    normalize3(cam.dir);
    camera_basis(&cam);
    cam.tan_y = tan(0.5 * fov_y_degrees * FS_PI / 180.0);
    cam.tan_x = cam.tan_y * W / H;

    /* bounding sphere of everything drawn */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const scene_mesh *all[2] = {&layer, &body};
    for (int k = 0; k < 2; k++)
        for (int32_t i = 0; i < all[k]->n_verts; i++)
            for (int q = 0; q < 3; q++) {
                lo[q] = fmin(lo[q], all[k]->pos[3 * (size_t)i + q]);
                hi[q] = fmax(hi[q], all[k]->pos[3 * (size_t)i + q]);
            }
    double centre[3], radius = 0.0;
    for (int q = 0; q < 3; q++) {
        centre[q] = 0.5 * (lo[q] + hi[q]);
        radius += 0.25 * (hi[q] - lo[q]) * (hi[q] - lo[q]);
    }
    radius = sqrt(radius);
    memcpy(cam.target, centre, sizeof centre);
    camera_fit(&cam, all, 2, radius);

    /* key light from the upper left, a little in front */
    double horiz[3] = {cam.dir[0], cam.dir[1], cam.dir[2]}, light[3];
    double along_up = fs_dot3(horiz, cam.up);
    for (int q = 0; q < 3; q++)
        horiz[q] -= along_up * cam.up[q];
    normalize3(horiz);
    for (int q = 0; q < 3; q++)
        light[q] = -0.55 * cam.right[q] + 0.70 * cam.up[q] - 0.45 * horiz[q];
    normalize3(light);

    fs_osmesa_scene scene = {
        .light_rgb = {2.15f, 2.07f, 1.95f},
        .sky_rgb = {0.26f, 0.29f, 0.35f},
        .ground_rgb = {0.08f, 0.07f, 0.06f},
        .specular = 0.05f,
        .shininess = 48.0f,
        .shadow_size = SHADOW_SIZE,
        .shadow_offset = (float)(3.0 * radius / SHADOW_SIZE),
    };
    for (int q = 0; q < 3; q++) {
        scene.eye[q] = (float)(cam.target[q] - cam.distance * cam.dir[q]);
        scene.light_dir[q] = (float)light[q];
        scene.up[q] = (float)cam.up[q];
    }
    light_matrix(light, centre, radius * 1.02, scene.shadow_from_world);
    fs_osmesa_mesh meshes[2];
    for (int k = 0; k < 2; k++)
        meshes[k] = (fs_osmesa_mesh){all[k]->n_verts, all[k]->pos,   all[k]->normal, all[k]->uv,
                                     all[k]->tint,    all[k]->tangent, all[k]->n_tris, all[k]->tri};
    fs_osmesa_texture tex = {maps->basecolor.width,
                             maps->basecolor.height,
                             maps->basecolor.data,
                             maps->normal.width,
                             maps->normal.height,
                             maps->normal.data,
                             p->normal == FS_NORMAL_DIRECTX ? -1.0f : 1.0f,
                             fs_domain_wraps_u(&d),
                             fs_domain_wraps_v(&d)};

    int tw = W < TILE_PIXELS ? W : TILE_PIXELS, th = H < TILE_PIXELS ? H : TILE_PIXELS;
    int rc = 0;
    fs_osmesa *g = fs_osmesa_create(tw, th);
    if (!g || fs_osmesa_lit_load(g, &scene, meshes, 2, &tex) < 0)
        rc = -1;
    fs_image_alloc(out, W, H, 3, FS_PIX_U8);
    uint8_t *px = out->data;
    for (int py0 = 0; rc == 0 && py0 < H; py0 += th) {
        for (int px0 = 0; rc == 0 && px0 < W; px0 += tw) {
            double x0 = 2.0 * px0 / W - 1.0, x1 = 2.0 * (px0 + tw) / W - 1.0;
            double y1 = 1.0 - 2.0 * py0 / H, y0 = 1.0 - 2.0 * (py0 + th) / H;
            float clip[16];
            camera_matrix(&cam, x0, x1, y0, y1, clip);
            const float *buf = NULL;
            if (fs_osmesa_lit_draw(g, clip) < 0 || !(buf = fs_osmesa_finish(g))) {
                rc = -1;
                break;
            }
            for (int j = 0; j < th && py0 + j < H; j++) {
                const float *row = buf + 4 * (size_t)(th - 1 - j) * (size_t)tw;
                for (int i = 0; i < tw && px0 + i < W; i++) {
                    const float *s = row + 4 * (size_t)i;
                    double bg[3], a = s[3] < 0.0f ? 0.0 : (s[3] > 1.0f ? 1.0 : s[3]);
                    backdrop(px0 + i, py0 + j, W, H, bg);
                    uint8_t *o = px + 3 * ((size_t)(py0 + j) * (size_t)W + (size_t)(px0 + i));
                    for (int q = 0; q < 3; q++)
                        o[q] = to_byte(tone_map(s[q] + (1.0 - a) * bg[q]));
                }
            }
        }
    }
    fs_osmesa_destroy(g);
    mesh_free(&layer);
    mesh_free(&body);
    free(edges);
    fs_lifted_mesh_free(&l);
    if (rc < 0)
        fs_image_free(out);
    return rc;
}
