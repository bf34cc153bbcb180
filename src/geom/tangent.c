/* Tangent frames from texture coordinates, after MikkTSpace's construction (see tangent.h). */
#include "geom/tangent.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "base/error.h"

static void load3(double *d, const float *s)
{
    d[0] = s[0];
    d[1] = s[1];
    d[2] = s[2];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* a minus its component along the unit vector n. */
static void reject(double *a, const double *n)
{
    double d = dot3(a, n);
    for (int q = 0; q < 3; q++)
        a[q] -= d * n[q];
}

/* Normalises a; returns false (leaving a) when it is too short to have a direction. */
static bool normalize(double *a)
{
    double len = sqrt(dot3(a, a));
    if (!(len > 1e-20))
        return false;
    for (int q = 0; q < 3; q++)
        a[q] /= len;
    return true;
}

/* A unit vector perpendicular to the unit vector n: the coordinate axis least aligned with n, made
 * perpendicular. */
static void any_perpendicular(const double *n, double *t)
{
    int axis = 0;
    for (int q = 1; q < 3; q++)
        if (fabs(n[q]) < fabs(n[axis]))
            axis = q;
    t[0] = t[1] = t[2] = 0.0;
    t[axis] = 1.0;
    reject(t, n);
    normalize(t);
}

/* design: as in MikkTSpace (Mikkelsen, "Simulation of wrinkled surfaces revisited", 2008), each
 * triangle contributes at each corner the direction of dP/du, made perpendicular to the corner's
 * vertex normal, weighted by the corner's angle measured in that normal's plane; a triangle's
 * handedness is the sign of its area in uv, and the triangles of one vertex are summed by
 * handedness, the mirrored ones into a copy of the vertex. */
int32_t fs_tangents_build(const float *pos, const float *normal, const float *uv, const int32_t *pos_id,
                          int32_t n_vert, uint32_t *tri, int32_t n_tris, int32_t **source, float **tangent)
{
    int8_t *orient = fs_calloc((size_t)n_tris + 1, sizeof *orient);
    double *face_t = fs_calloc(3 * (size_t)n_tris + 1, sizeof *face_t);
    uint8_t *mask = fs_calloc((size_t)n_vert + 1, 1);
    for (int32_t f = 0; f < n_tris; f++) {
        const uint32_t *c = tri + 3 * (size_t)f;
        double p0[3], p1[3], p2[3];
        load3(p0, pos + 3 * (size_t)c[0]);
        load3(p1, pos + 3 * (size_t)c[1]);
        load3(p2, pos + 3 * (size_t)c[2]);
        const float *t0 = uv + 2 * (size_t)c[0], *t1 = uv + 2 * (size_t)c[1], *t2 = uv + 2 * (size_t)c[2];
        double s1u = (double)t1[0] - t0[0], s1v = (double)t1[1] - t0[1];
        double s2u = (double)t2[0] - t0[0], s2v = (double)t2[1] - t0[1];
        double area = s1u * s2v - s1v * s2u;
        double *t = face_t + 3 * (size_t)f;
        for (int q = 0; q < 3; q++)
            t[q] = s2v * (p1[q] - p0[q]) - s1v * (p2[q] - p0[q]);
        if (area == 0.0 || !normalize(t)) {
            t[0] = t[1] = t[2] = 0.0;
            continue;
        }
        orient[f] = area > 0.0 ? 1 : -1;
        if (area < 0.0)
            for (int q = 0; q < 3; q++)
                t[q] = -t[q];
        for (int k = 0; k < 3; k++)
            mask[c[k]] |= area > 0.0 ? 1 : 2;
    }

    /* Vertices used both ways get a mirrored copy. */
    int32_t n_out = n_vert;
    int32_t *twin = fs_malloc(((size_t)n_vert + 1) * sizeof *twin);
    for (int32_t v = 0; v < n_vert; v++)
        twin[v] = mask[v] == 3 ? n_out++ : -1;
    int32_t *src = fs_malloc(((size_t)n_out + 1) * sizeof *src);
    int8_t *sign = fs_malloc((size_t)n_out + 1);
    for (int32_t v = 0; v < n_vert; v++) {
        src[v] = v;
        sign[v] = mask[v] == 2 ? -1 : 1;
        if (twin[v] >= 0) {
            src[twin[v]] = v;
            sign[twin[v]] = -1;
        }
    }
    for (int32_t f = 0; f < n_tris; f++)
        if (orient[f] < 0)
            for (int k = 0; k < 3; k++) {
                uint32_t *c = tri + 3 * (size_t)f + k;
                if (twin[*c] >= 0)
                    *c = (uint32_t)twin[*c];
            }

    double *acc = fs_calloc(3 * (size_t)n_out + 1, sizeof *acc);
    for (int32_t f = 0; f < n_tris; f++) {
        if (!orient[f])
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t v = tri[3 * (size_t)f + k];
            int32_t s = src[v];
            double n[3], t[3], p[3], e1[3], e2[3];
            load3(n, normal + 3 * (size_t)s);
            memcpy(t, face_t + 3 * (size_t)f, sizeof t);
            reject(t, n);
            if (!normalize(t))
                continue;
            load3(p, pos + 3 * (size_t)s);
            load3(e1, pos + 3 * (size_t)src[tri[3 * (size_t)f + (k + 1) % 3]]);
            load3(e2, pos + 3 * (size_t)src[tri[3 * (size_t)f + (k + 2) % 3]]);
            for (int q = 0; q < 3; q++) {
                e1[q] -= p[q];
                e2[q] -= p[q];
            }
            reject(e1, n);
            reject(e2, n);
            if (!normalize(e1) || !normalize(e2))
                continue;
            double c = dot3(e1, e2);
            double angle = acos(c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c);
            for (int q = 0; q < 3; q++)
                acc[3 * (size_t)v + q] += angle * t[q];
        }
    }

    float *out = fs_malloc((4 * (size_t)n_out + 1) * sizeof *out);
    uint8_t *have = fs_calloc((size_t)n_out + 1, 1);
    int32_t n_ids = 0;
    for (int32_t v = 0; v < n_out; v++) {
        have[v] = normalize(acc + 3 * (size_t)v);
        if (pos_id && pos_id[src[v]] >= n_ids)
            n_ids = pos_id[src[v]] + 1;
    }
    /* The copies of a point pass their tangents to those that have none. */
    double *by_point = pos_id ? fs_calloc(3 * (size_t)n_ids + 1, sizeof *by_point) : NULL;
    if (pos_id)
        for (int32_t v = 0; v < n_out; v++)
            if (have[v])
                for (int q = 0; q < 3; q++)
                    by_point[3 * (size_t)pos_id[src[v]] + q] += acc[3 * (size_t)v + q];
    for (int32_t v = 0; v < n_out; v++) {
        double *t = acc + 3 * (size_t)v;
        if (!have[v]) {
            double n[3];
            load3(n, normal + 3 * (size_t)src[v]);
            bool ok = false;
            if (pos_id) {
                memcpy(t, by_point + 3 * (size_t)pos_id[src[v]], 3 * sizeof *t);
                double before = sqrt(dot3(t, t));
                reject(t, n);
                ok = before > 0.0 && sqrt(dot3(t, t)) > 1e-3 * before && normalize(t);
            }
            if (!ok)
                any_perpendicular(n, t);
        }
        for (int q = 0; q < 3; q++)
            out[4 * (size_t)v + q] = (float)t[q];
        out[4 * (size_t)v + 3] = (float)sign[v];
    }
    free(by_point);
    free(have);
    free(acc);
    free(sign);
    free(twin);
    free(mask);
    free(face_t);
    free(orient);
    *source = src;
    *tangent = out;
    return n_out;
}
