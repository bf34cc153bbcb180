/* Test helper: is a Wavefront OBJ written by --mesh a well-formed, correctly bounded lift of the domain? */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Usage: obj_check FILE plane W H DEPTH | cylinder R H DEPTH | sphere R DEPTH  [leaning]
 * Reads the file on its own (independently of the writer) and checks, printing one line per
 * failure and a summary "V E F euler components boundary":
 *  - every face is a triangle "f p/t/n p/t/n p/t/n" with indices in range;
 *  - texture coordinates lie in [0, 1], normals are unit, no two positions are closer than the weld
 *    tolerance unless they are equal: equal ones are copies where fragments touch (at most 2 % of
 *    the positions);
 *  - every edge is shared by at most two triangles, running opposite ways (consistent orientation),
 *    so each fragment's surface is a manifold;
 *  - boundary edges lie only on the domain's borders: the four sides of a plane (a tile is a flat
 *    slab in 3-D), the two ends of a cylinder; a sphere has none;
 *  - with equal positions taken as one, the surface is one piece with the Euler characteristic of a
 *    disk (plane, 1), an open tube (cylinder, 0) or a sphere (2);
 *  - each corner sits where its texture coordinate says (plane (u W, v H), cylinder angle 2 pi u and
 *    z = v H, sphere longitude 2 pi u and latitude pi v - pi/2), at a height in [0, DEPTH] above the
 *    domain surface along its normal;
 *  - corner normals point to the side the triangle faces, and triangles of group "layer" face
 *    outwards (away from the plane's underside, the cylinder's axis, the sphere's centre; a sloping
 *    face rising across the layer on the cylinder or the sphere, as a crack's sloping wall, may lean
 *    over by 6 degrees), unless
 *    "leaning" is given: for the springs model's relaxed cells, whose own walls can lean over their
 *    bases and whose tops can cross themselves where the post-process pushed a corner over a side
 *    (model/springs/post.c), the facing of "layer" triangles is not checked (everything else is). */

#define PI 3.14159265358979323846

typedef struct {
    int32_t p[3], t[3], n[3];
    int wall;
} face;

typedef struct {
    int32_t a, b; /* a < b */
    int32_t f;
    int8_t forward; /* the face runs a -> b */
} edge;

static int failures;

static void fail(const char *fmt, double a, double b)
{
    if (failures < 20) {
        printf("FAIL ");
        printf(fmt, a, b);
        putchar('\n');
    }
    failures++;
}

static int cmp_edge(const void *x, const void *y)
{
    const edge *a = x, *b = y;
    if (a->a != b->a)
        return a->a < b->a ? -1 : 1;
    if (a->b != b->b)
        return a->b < b->b ? -1 : 1;
    return a->f < b->f ? -1 : (a->f > b->f);
}

static double dist2(const double *a, const double *b)
{
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

static int32_t find(int32_t *parent, int32_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

typedef struct {
    int type; /* 0 plane, 1 cylinder, 2 sphere */
    double w, h, r, depth, tol;
} domain;

/* Height of p above the domain surface, and its outward normal there. */
static double height_of(const domain *d, const double *p, double *n)
{
    if (d->type == 0) {
        n[0] = n[1] = 0.0;
        n[2] = 1.0;
        return p[2];
    }
    if (d->type == 1) {
        double rho = hypot(p[0], p[1]);
        n[0] = p[0] / rho;
        n[1] = p[1] / rho;
        n[2] = 0.0;
        return rho - d->r;
    }
    double rho = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int q = 0; q < 3; q++)
        n[q] = p[q] / rho;
    return rho - d->r;
}

/* Distance of two texture u values on a wrapping axis. */
static double wrap_dist(double a, double b)
{
    double d = fabs(a - b);
    d -= floor(d);
    return d < 1.0 - d ? d : 1.0 - d;
}

static void check_corner(const domain *d, const double *p, const float *uv)
{
    double n[3], h = height_of(d, p, n);
    if (h < -d->tol || h > d->depth + d->tol)
        fail("a position lies %g cm above the surface, outside [0, %g]", h, d->depth);
    double u = uv[0], v = uv[1];
    if (d->type == 0) {
        if (fabs(p[0] - u * d->w) > d->tol || fabs(p[1] - v * d->h) > d->tol)
            fail("a plane corner is %g cm off its texture point (u = %g)", hypot(p[0] - u * d->w, p[1] - v * d->h), u);
    } else if (d->type == 1) {
        double a = atan2(p[1], p[0]) / (2.0 * PI);
        if (wrap_dist(a, u) * 2.0 * PI * d->r > d->tol || fabs(p[2] - v * d->h) > d->tol)
            fail("a cylinder corner is off its texture point (angle %g, u %g)", a, u);
    } else {
        double lat = asin(fmax(-1.0, fmin(1.0, n[2])));
        if (fabs((lat + PI / 2) / PI - v) * PI * d->r > d->tol)
            fail("a sphere corner is off its texture latitude (v %g, latitude %g)", v, lat);
        if (cos(lat) > 1e-3 && wrap_dist(atan2(p[1], p[0]) / (2.0 * PI), u) * 2.0 * PI * d->r * cos(lat) > d->tol)
            fail("a sphere corner is off its texture longitude (u %g, v %g)", u, v);
    }
}

/* Whether position p lies on a border of the domain where the layer may end. */
static int on_border(const domain *d, const double *p)
{
    if (d->type == 0)
        return fabs(p[0]) <= d->tol || fabs(p[0] - d->w) <= d->tol || fabs(p[1]) <= d->tol ||
               fabs(p[1] - d->h) <= d->tol;
    if (d->type == 1)
        return fabs(p[2]) <= d->tol || fabs(p[2] - d->h) <= d->tol;
    return 0;
}

/* Whether both ends lie on the same border line. */
static int same_border(const domain *d, const double *p, const double *q)
{
    if (d->type == 0) {
        double x[4] = {0.0, d->w, 0.0, d->h};
        for (int k = 0; k < 4; k++) {
            int axis = k / 2;
            if (fabs(p[axis] - x[k]) <= d->tol && fabs(q[axis] - x[k]) <= d->tol)
                return 1;
        }
        return 0;
    }
    if (d->type == 1)
        return (fabs(p[2]) <= d->tol && fabs(q[2]) <= d->tol) ||
               (fabs(p[2] - d->h) <= d->tol && fabs(q[2] - d->h) <= d->tol);
    return 0;
}

int main(int argc, char **argv)
{
    domain d = {0};
    if (argc >= 6 && !strcmp(argv[2], "plane")) {
        d.type = 0;
        d.w = atof(argv[3]);
        d.h = atof(argv[4]);
        d.depth = atof(argv[5]);
    } else if (argc >= 6 && !strcmp(argv[2], "cylinder")) {
        d.type = 1;
        d.r = atof(argv[3]);
        d.h = atof(argv[4]);
        d.depth = atof(argv[5]);
    } else if (argc >= 5 && !strcmp(argv[2], "sphere")) {
        d.type = 2;
        d.r = atof(argv[3]);
        d.depth = atof(argv[4]);
    } else {
        fprintf(stderr, "usage: obj_check FILE plane W H DEPTH | cylinder R H DEPTH | sphere R DEPTH [leaning]\n");
        return 2;
    }
    int n_args = d.type == 2 ? 5 : 6;
    int leaning = argc > n_args && !strcmp(argv[n_args], "leaning");
    double size = d.type == 0 ? fmax(d.w, d.h) : (d.type == 1 ? fmax(2 * PI * d.r, d.h) : 2 * PI * d.r);
    d.tol = 2e-5 * size;

    FILE *f = fopen(argv[1], "r");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    double *pos = NULL;
    float *uv = NULL, *nrm = NULL;
    face *fc = NULL;
    int32_t np = 0, nt = 0, nn = 0, nf = 0, cp = 0, ct = 0, cn = 0, cf = 0;
    int wall = 0;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "v ", 2)) {
            if (np == cp)
                pos = realloc(pos, 3 * sizeof *pos * (size_t)(cp = cp ? 2 * cp : 1024));
            if (sscanf(line + 2, "%lf %lf %lf", pos + 3 * np, pos + 3 * np + 1, pos + 3 * np + 2) != 3)
                fail("bad vertex line (v %g)%.0g", np + 1, 0);
            np++;
        } else if (!strncmp(line, "vt ", 3)) {
            if (nt == ct)
                uv = realloc(uv, 2 * sizeof *uv * (size_t)(ct = ct ? 2 * ct : 1024));
            if (sscanf(line + 3, "%f %f", uv + 2 * nt, uv + 2 * nt + 1) != 2)
                fail("bad texture line (vt %g)%.0g", nt + 1, 0);
            for (int q = 0; q < 2; q++)
                if (!(uv[2 * nt + q] >= 0.0f && uv[2 * nt + q] <= 1.0f))
                    fail("texture coordinate %g outside [0, 1] (vt %g)", uv[2 * nt + q], nt + 1);
            nt++;
        } else if (!strncmp(line, "vn ", 3)) {
            if (nn == cn)
                nrm = realloc(nrm, 3 * sizeof *nrm * (size_t)(cn = cn ? 2 * cn : 1024));
            float *n = nrm + 3 * nn;
            if (sscanf(line + 3, "%f %f %f", n, n + 1, n + 2) != 3)
                fail("bad normal line (vn %g)%.0g", nn + 1, 0);
            double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (fabs(len - 1.0) > 1e-5)
                fail("normal %g has length %g", nn + 1, len);
            nn++;
        } else if (!strncmp(line, "g ", 2)) {
            wall = !strncmp(line + 2, "walls", 5);
        } else if (!strncmp(line, "f ", 2)) {
            if (nf == cf)
                fc = realloc(fc, sizeof *fc * (size_t)(cf = cf ? 2 * cf : 1024));
            face *x = fc + nf;
            int got = sscanf(line + 2, "%d/%d/%d %d/%d/%d %d/%d/%d", &x->p[0], &x->t[0], &x->n[0], &x->p[1], &x->t[1],
                             &x->n[1], &x->p[2], &x->t[2], &x->n[2]);
            if (got != 9) {
                fail("face %g is not a triangle with p/t/n corners (%g fields)", nf + 1, got);
                continue;
            }
            for (int k = 0; k < 3; k++) {
                x->p[k]--;
                x->t[k]--;
                x->n[k]--;
                if (x->p[k] < 0 || x->p[k] >= np || x->t[k] < 0 || x->t[k] >= nt || x->n[k] < 0 || x->n[k] >= nn)
                    fail("face %g has an index out of range (corner %g)", nf + 1, k);
            }
            x->wall = wall;
            nf++;
        }
    }
    fclose(f);
    if (failures) {
        printf("%d failure(s) reading %s\n", failures, argv[1]);
        return 1;
    }

    /* Distinct positions: sort by x and compare neighbours within the tolerance. */
    int32_t *order = malloc(sizeof *order * (size_t)(np + 1));
    for (int32_t i = 0; i < np; i++)
        order[i] = i;
    for (int32_t gap = np / 2; gap > 0; gap /= 2) /* shell sort: no comparator state needed */
        for (int32_t i = gap; i < np; i++)
            for (int32_t j = i; j >= gap && pos[3 * order[j - gap]] > pos[3 * order[j]]; j -= gap) {
                int32_t t = order[j];
                order[j] = order[j - gap];
                order[j - gap] = t;
            }
    double weld = 1e-7 * size;
    int32_t *canon = malloc(sizeof *canon * (size_t)(np + 1)); /* equal positions as one */
    for (int32_t i = 0; i < np; i++)
        canon[i] = i;
    int32_t copies = 0;
    for (int32_t i = 0; i < np; i++)
        for (int32_t j = i + 1; j < np && pos[3 * order[j]] - pos[3 * order[i]] <= weld; j++) {
            const double *a = pos + 3 * order[i], *b = pos + 3 * order[j];
            double dd = sqrt(dist2(a, b));
            if (dd == 0.0) {
                int32_t ra = find(canon, order[i]), rb = find(canon, order[j]);
                copies += ra != rb;
                if (ra != rb)
                    canon[ra < rb ? rb : ra] = ra < rb ? ra : rb;
            } else if (dd <= weld) {
                fail("positions %g apart are not welded (at x = %g)", dd, a[0]);
            }
        }
    free(order);
    if (copies > np / 50)
        fail("%g of %g positions are copies of others", copies, np);

    /* Corners, normals and facing. */
    for (int32_t i = 0; i < nf; i++) {
        const face *x = fc + i;
        const double *p[3] = {pos + 3 * x->p[0], pos + 3 * x->p[1], pos + 3 * x->p[2]};
        double e1[3], e2[3], fn[3];
        for (int q = 0; q < 3; q++) {
            e1[q] = p[1][q] - p[0][q];
            e2[q] = p[2][q] - p[0][q];
        }
        fn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        fn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        fn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double area2 = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
                double longest2 = 0.0;
        for (int k = 0; k < 3; k++) {
            const double *p0 = p[k], *p1 = p[(k + 1) % 3];
            double l2 = dist2(p0, p1);
            longest2 = l2 > longest2 ? l2 : longest2;
        }
        for (int k = 0; k < 3; k++) {
            check_corner(&d, p[k], uv + 2 * x->t[k]);
            const float *n = nrm + 3 * x->n[k];
            if (area2 > 1e-2 * longest2 && n[0] * fn[0] + n[1] * fn[1] + n[2] * fn[2] <= 0.0)
                fail("a corner normal of face %g points against its face (%g)", i + 1, 0);
        }
        /* triangles with no area in texture space (upright slivers along a border) face sideways */
        const float *t0 = uv + 2 * x->t[0], *t1 = uv + 2 * x->t[1], *t2 = uv + 2 * x->t[2];
        double uv_area2 =
            fabs(((double)t1[0] - t0[0]) * ((double)t2[1] - t0[1]) - ((double)t1[1] - t0[1]) * ((double)t2[0] - t0[0]));
        /* needles (width below 1% of their length) have no meaningful facing */
        /* nor do triangles touching a pole of the sphere, where the texture map is singular */
        int at_pole = 0;
        for (int k = 0; k < 3 && d.type == 2; k++)
            at_pole = at_pole || hypot(p[k][0], p[k][1]) < 1e-3 * d.r;
        if (!x->wall && !leaning && !at_pole && area2 > 1e-2 * longest2 && uv_area2 > 1e-10) {
            double c[3], up[3];
            for (int q = 0; q < 3; q++)
                c[q] = (p[0][q] + p[1][q] + p[2][q]) / 3.0;
            height_of(&d, c, up);
            double facing = (fn[0] * up[0] + fn[1] * up[1] + fn[2] * up[2]) / area2;
            /* walls a model drew itself (the springs cells' sides) stand upright: within a degree of
             * vertical, rounding decides the sign. A crack's sloping wall ([render] wall_slope) runs
             * from a top's edge down to the floor over a few hundredths of a millimetre: on the
             * cylinder and the sphere its long top edge is a chord, which sags inwards by more than
             * that, so the nearly upright face may lean over by a few degrees. */
            double lowest = INFINITY, highest = -INFINITY, dummy[3];
            for (int k = 0; k < 3; k++) {
                double hk = height_of(&d, p[k], dummy);
                lowest = hk < lowest ? hk : lowest;
                highest = hk > highest ? hk : highest;
            }
            bool slope = d.type != 0 && highest - lowest > 1e-3 * d.depth;
            if (facing <= (slope ? -0.1 : -0.02))
                fail("layer face %g faces inwards (cosine %g)", i + 1, facing);
        }
    }

    /* Edges: sorted by their ends, at most two faces each, opposite ways. */
    edge *e = malloc(sizeof *e * (3 * (size_t)nf + 1));
    for (int32_t i = 0; i < nf; i++)
        for (int k = 0; k < 3; k++) {
            int32_t a = fc[i].p[k], b = fc[i].p[(k + 1) % 3];
            if (a == b)
                fail("face %g repeats a position (corner %g)", i + 1, k);
            e[3 * i + k] = (edge){a < b ? a : b, a < b ? b : a, i, (int8_t)(a < b)};
        }
    qsort(e, 3 * (size_t)nf, sizeof *e, cmp_edge);
    int32_t *parent = malloc(sizeof *parent * (size_t)(nf + 1));
    for (int32_t i = 0; i < nf; i++)
        parent[i] = i;
    int32_t n_edges = 0, n_boundary = 0;
    for (size_t i = 0; i < 3 * (size_t)nf;) {
        size_t j = i + 1;
        while (j < 3 * (size_t)nf && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        n_edges++;
        if (j - i > 2)
            fail("an edge is shared by %g triangles (position %g)", (double)(j - i), e[i].a + 1);
        else if (j - i == 2) {
            if (e[i].forward == e[i + 1].forward)
                fail("two triangles run the same way along an edge (positions %g, %g)", e[i].a + 1, e[i].b + 1);
            int32_t ra = find(parent, e[i].f), rb = find(parent, e[i + 1].f);
            if (ra != rb)
                parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        } else {
            n_boundary++;
            const double *p = pos + 3 * e[i].a, *q = pos + 3 * e[i].b;
            if (!same_border(&d, p, q))
                fail("a boundary edge lies off the domain's borders (at %g, %g)", p[0], p[1]);
        }
        i = j;
    }
    /* pieces and the Euler characteristic with equal positions taken as one */
    for (int32_t i = 0; i < nf; i++)
        for (int k = 0; k < 3; k++) {
            int32_t a = find(canon, fc[i].p[k]), b = find(canon, fc[i].p[(k + 1) % 3]);
            e[3 * i + k] = (edge){a < b ? a : b, a < b ? b : a, i, (int8_t)(a < b)};
        }
    qsort(e, 3 * (size_t)nf, sizeof *e, cmp_edge);
    for (int32_t i = 0; i < nf; i++)
        parent[i] = i;
    n_edges = 0;
    for (size_t i = 0; i < 3 * (size_t)nf;) {
        size_t j = i + 1;
        while (j < 3 * (size_t)nf && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        n_edges++;
        for (size_t q = i + 1; q < j; q++) {
            int32_t ra = find(parent, e[i].f), rb = find(parent, e[q].f);
            if (ra != rb)
                parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        }
        i = j;
    }
    int32_t components = 0;
    for (int32_t i = 0; i < nf; i++)
        components += find(parent, i) == i;
    char *used = calloc((size_t)np + 1, 1);
    int32_t n_used = 0;
    for (int32_t i = 0; i < nf; i++)
        for (int k = 0; k < 3; k++) {
            int32_t v = find(canon, fc[i].p[k]);
            if (!used[v]) {
                used[v] = 1;
                n_used++;
            }
        }
    for (int32_t i = 0; i < np; i++)
        if (used[i] && d.type == 2 && on_border(&d, pos + 3 * i))
            fail("a sphere position lies on a border (position %g)%.0g", i + 1, 0);
    long euler = (long)n_used - n_edges + nf;
    long want = d.type == 0 ? 1 : (d.type == 1 ? 0 : 2);
    if (components != 1)
        fail("the surface is in %g pieces, expected %g", components, 1);
    if (euler != want)
        fail("Euler characteristic V - E + F = %g, expected %g", (double)euler, (double)want);
    if (d.type == 2 && n_boundary)
        fail("a sphere has %g boundary edges, expected %g", n_boundary, 0);
    printf("V=%d E=%d F=%d euler=%ld components=%d boundary=%d copies=%d\n", (int)n_used, (int)n_edges, (int)nf,
           euler, (int)components, (int)n_boundary, (int)copies);
    free(used);
    free(canon);
    free(parent);
    free(e);
    free(pos);
    free(uv);
    free(nrm);
    free(fc);
    if (failures) {
        printf("%d failure(s)\n", failures);
        return 1;
    }
    return 0;
}
