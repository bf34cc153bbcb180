/* Point sampling: particle repulsion with perturbed force radii on a uniform grid, and the hex lattice. */
#include "geom/sample.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/rng.h"
#include "base/threads.h"
#include "base/vec.h"

#define SAMPLE_MAX_COUNT 50000000

/* design: repulsion after thesis §5.2.1 (Algorithms 2-3). Each particle i has a force radius
 * r_i = r0 (1 + jitter (2u - 1)); two particles closer than rsum = r_i + r_j repel each other along
 * the line between them with magnitude 1 - (d / rsum)^2 (Eq. 5.1 is scrambled in our copy of the
 * thesis; this is the reading that grows as d shrinks, vanishes at rsum and stays bounded). The mean
 * rsum = 2 r0 is 1.1 x the hex spacing, under the thesis' bound 3.2 sqrt(A / (n pi)) ~ 1.68 x, so the
 * points jam evenly without forming a lattice; the value was tuned for the largest nearest-neighbour
 * distances after 30 iterations. Each iteration is a Jacobi step: every force from one snapshot, then
 * each particle moves by step * force, the move capped at a fraction of the spacing; step and cap
 * shrink linearly over the iterations (damping). A particle pushed over a non-periodic side is
 * snapped onto it, one pushed over a periodic side re-enters on the other (thesis §5.2.1).
 * The snapshot is bucketed by a stable counting sort into a uniform grid of cells at least
 * dmax = 2 max r_i wide, so only neighbouring cells are searched and an iteration costs O(n); the
 * particles stay in bucket order between iterations, so memory is walked nearly sequentially. Each
 * pair is visited once, from one end of a half stencil, and its force added to both ends. Cells and
 * particles are visited in a fixed order, so every sum is reduced in the same order for a seed.
 * Plane and cylinder (the unwrapped rectangle) work in 2-D; a periodic side wraps the grid and a
 * neighbouring cell carries the shift of its periodic image. The sphere works in 3-D on the cells of
 * the bounding cube that the sphere passes through (a sparse grid: per column of the cube, one or two
 * runs of cells), and points are projected back onto the sphere after every move. */

/* Mean interaction distance 2 r0 relative to fs_sample_spacing. */
#define RSUM_OVER_SPACING 1.1
/* Move per unit force and largest move, in spacings, at the first iteration... */
#define STEP0 0.6
#define MAXMOVE0 0.5
/* ...decaying linearly to this fraction at the last iteration. */
#define DAMP_END 0.25

fs_sample_params fs_sample_params_default(void)
{
    fs_sample_params p = {.count = 1000, .iterations = 30, .radius_jitter = 0.2, .seed = 1};
    return p;
}

double fs_sample_spacing(const fs_domain *d, int32_t count)
{
    if (count <= 0)
        return 0.0;
    return sqrt(2.0 * fs_domain_area(d) / (sqrt(3.0) * (double)count));
}

void fs_points_free(fs_points *pts)
{
    if (!pts)
        return;
    free(pts->p);
    pts->p = NULL;
    pts->n = 0;
}

static bool positive_finite(double v) { return isfinite(v) && v > 0.0; }

static int bad_length(const char *what, const char *field, double v)
{
    fs_error(FS_ERR_DATA, "%s: domain %s must be a positive finite length (cm), got %g", what, field, v);
    return -1;
}

/* Checks the fields of a domain that the samplers use; the error names the first bad one. */
static int check_domain(const char *what, const fs_domain *d)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
        if (!positive_finite(d->width))
            return bad_length(what, "width", d->width);
        if (!positive_finite(d->height))
            return bad_length(what, "height", d->height);
        return 0;
    case FS_DOMAIN_CYLINDER:
        if (!positive_finite(d->radius))
            return bad_length(what, "radius", d->radius);
        if (!positive_finite(d->height))
            return bad_length(what, "height", d->height);
        return 0;
    case FS_DOMAIN_SPHERE:
        if (!positive_finite(d->radius))
            return bad_length(what, "radius", d->radius);
        return 0;
    case FS_DOMAIN_MESH:
        break; /* a mesh is loaded, not sampled */
    }
    fs_error(FS_ERR_DATA, "%s: unknown domain type %d", what, (int)d->type);
    return -1;
}

static int check_count(const char *what, int32_t count)
{
    if (count < 3) {
        fs_error(FS_ERR_DATA, "%s: expected at least 3 points, got %d", what, (int)count);
        return -1;
    }
    if (count > SAMPLE_MAX_COUNT) {
        fs_error(FS_ERR_DATA, "%s: expected at most %d points, got %d", what, SAMPLE_MAX_COUNT, (int)count);
        return -1;
    }
    return 0;
}

/* Particles [j0, j1) of the sorted snapshot and the shift that brings them next to the current cell
 * (their periodic image; zero on the sphere). */
typedef struct {
    int32_t j0, j1;
    double shift[2];
} neighbour;

/* Ranges of a half stencil: the own cell, then at most 4 in 2-D (the right cell, and the row above
 * in up to 3 periodic images) or 18 on the sphere (9 columns, two runs each). */
#define MAX_RANGES 20

/* Sphere: the cells of one column (ix, iy) of the bounding cube that the sphere passes through, as
 * up to two runs of iz (lower and upper cap; one run where they meet). Their buckets are consecutive
 * from `base`. */
typedef struct {
    int32_t base;
    int32_t lo[2], count[2];
} shell_column;

/* The working state of one repulsion run (struct of arrays). */
typedef struct {
    int32_t n;
    bool sphere;
    bool per[2];       /* plane/cylinder: periodic sides */
    double ext[2];     /* plane/cylinder: the rectangle */
    double radius;     /* sphere radius */
    double spacing;
    /* grid */
    int32_t dim[3];    /* cells per axis (dim[2] = 1 in 2-D) */
    double inv_cell;   /* 1 / cell width along each axis ... */
    double inv_cell_y; /* ... except y in 2-D */
    double origin;     /* sphere: -radius (the cube's corner); 2-D: 0 */
    shell_column *col; /* sphere: dim[0] * dim[1] columns */
    int32_t n_buckets;
    /* particles, in the order of the last bucket sort */
    double *x[3];
    double *r;
    int32_t *id;       /* the particle's index in the output */
    int32_t *key;      /* bucket of each particle this iteration */
    /* snapshot sorted by bucket */
    double *sx[3];
    double *sr;
    int32_t *sid;
    int32_t *start;    /* n_buckets + 1 */
    double *f[3];      /* force on each particle of the snapshot */
    int nthreads;      /* threads, and tasks of the per-particle passes (see MAX_THREADS) */
    int32_t *tcount;   /* nthreads * n_buckets: bucket counts of each task's particles */
} relax_state;

static int32_t cell_coord(double v, double origin, double inv, int32_t dim)
{
    double c = floor((v - origin) * inv);
    if (!(c >= 0.0))
        return 0;
    if (c >= (double)dim)
        return dim - 1;
    return (int32_t)c;
}

/* Sphere: the bucket of cell (ix, iy, iz), or -1 when the sphere does not pass through it. */
static int32_t shell_bucket(const relax_state *s, int32_t ix, int32_t iy, int32_t iz)
{
    const shell_column *c = &s->col[(size_t)iy * (size_t)s->dim[0] + (size_t)ix];
    if (iz >= c->lo[0] && iz < c->lo[0] + c->count[0])
        return c->base + iz - c->lo[0];
    if (iz >= c->lo[1] && iz < c->lo[1] + c->count[1])
        return c->base + c->count[0] + iz - c->lo[1];
    return -1;
}

/* The bucket of particle i in the current order. */
static int32_t particle_bucket(const relax_state *s, int32_t i)
{
    if (!s->sphere) {
        int32_t ix = cell_coord(s->x[0][i], 0.0, s->inv_cell, s->dim[0]);
        int32_t iy = cell_coord(s->x[1][i], 0.0, s->inv_cell_y, s->dim[1]);
        return iy * s->dim[0] + ix;
    }
    int32_t c[3];
    for (int a = 0; a < 3; a++)
        c[a] = cell_coord(s->x[a][i], s->origin, s->inv_cell, s->dim[a]);
    int32_t b = shell_bucket(s, c[0], c[1], c[2]);
    if (b >= 0)
        return b;
    /* rounding put the point just outside its column's runs (they have a margin): take the nearest */
    const shell_column *col = &s->col[(size_t)c[1] * (size_t)s->dim[0] + (size_t)c[0]];
    FS_ASSERT(col->count[0] + col->count[1] > 0);
    int32_t best = col->base, best_gap = INT32_MAX;
    for (int q = 0; q < 2; q++) {
        if (col->count[q] == 0)
            continue;
        int32_t z = c[2] < col->lo[q] ? col->lo[q] : col->lo[q] + col->count[q] - 1;
        int32_t gap = z > c[2] ? z - c[2] : c[2] - z;
        if (gap < best_gap) {
            best_gap = gap;
            best = col->base + (q ? col->count[0] : 0) + z - col->lo[q];
        }
    }
    return best;
}

/* design: the passes of an iteration run on up to fs_threads() threads (at most MAX_THREADS), each
 * pass one fs_parallel_for over its tasks (base/threads.h), and the result does not depend on the
 * thread count: per-particle passes split the particles into contiguous ranges (fs_parallel_part,
 * one range per thread), the bucket sort stays stable (each range counts its own buckets, and a range's
 * particles go after those of the ranges before it), and the force pass keeps the sequential order
 * of every floating-point sum (see all_forces). */
#define MAX_THREADS 8
/* The force pass is cut into this many bands per thread, so that a thread held up by other work
 * on the machine delays the pass by a smaller share. */
#define BANDS_PER_THREAD 4
#define MAX_BANDS (BANDS_PER_THREAD * MAX_THREADS)
/* Below this many particles everything runs on the calling thread. */
#define PARALLEL_MIN_COUNT 20000

/* A force on snapshot particle j, kept back by a force task (see all_forces). */
typedef struct {
    int32_t j;
    double v[3];
} force_entry;

/* One task of a parallel pass: particles [i0, i1), or grid rows [row0, row1) for the forces. */
typedef struct {
    relax_state *s;
    int t;
    int32_t i0, i1;
    int32_t row0, row1;
    int32_t log_below;  /* forces on snapshot particles before this index go to the log */
    force_entry *log;   /* those forces, in the order this task computed them */
    int32_t n_log, cap_log;
    double step, maxmove;
} relax_task;

/* Splits the particles into s->nthreads contiguous ranges. */
static void particle_tasks(relax_state *s, relax_task *task)
{
    for (int t = 0; t < s->nthreads; t++) {
        memset(&task[t], 0, sizeof task[t]);
        task[t].s = s;
        task[t].t = t;
        fs_parallel_part(s->n, s->nthreads, t, &task[t].i0, &task[t].i1);
    }
}

/* Bucket sort, first pass: the bucket of each particle of the range, counted per range. */
static void sort_keys(void *tasks, int32_t item)
{
    relax_task *task = (relax_task *)tasks + item;
    relax_state *s = task->s;
    int32_t *count = s->tcount + (size_t)task->t * (size_t)s->n_buckets;
    memset(count, 0, (size_t)s->n_buckets * sizeof *count);
    for (int32_t i = task->i0; i < task->i1; i++) {
        int32_t b = particle_bucket(s, i);
        s->key[i] = b;
        count[b]++;
    }
}

/* Bucket sort, last pass: each particle of the range to its place in the snapshot (its range's
 * count array now holds where the range's next particle of each bucket goes); clears the forces. */
static void sort_scatter(void *tasks, int32_t item)
{
    relax_task *task = (relax_task *)tasks + item;
    relax_state *s = task->s;
    int dims = s->sphere ? 3 : 2;
    int32_t *next = s->tcount + (size_t)task->t * (size_t)s->n_buckets;
    for (int32_t i = task->i0; i < task->i1; i++) {
        int32_t k = next[s->key[i]]++;
        for (int a = 0; a < dims; a++)
            s->sx[a][k] = s->x[a][i];
        s->sr[k] = s->r[i];
        s->sid[k] = s->id[i];
    }
    for (int a = 0; a < dims; a++)
        memset(s->f[a] + task->i0, 0, (size_t)(task->i1 - task->i0) * sizeof(double));
}

/* Stable counting sort of the particles into buckets (the snapshot and start), with the forces
 * cleared for the next force pass. */
static void bucket_sort(relax_state *s)
{
    relax_task task[MAX_THREADS];
    int32_t nb = s->n_buckets;
    int nt = s->nthreads;
    particle_tasks(s, task);
    fs_parallel_for(nt, nt, sort_keys, task);
    int32_t sum = 0;
    for (int32_t b = 0; b < nb; b++) {
        s->start[b] = sum;
        for (int t = 0; t < nt; t++) {
            int32_t *c = s->tcount + (size_t)t * (size_t)nb + b;
            int32_t count = *c;
            *c = sum;
            sum += count;
        }
    }
    s->start[nb] = sum;
    fs_parallel_for(nt, nt, sort_scatter, task);
}

/* Appends particles [j0, j1) with a shift to a list of ranges, merging it into the last range when
 * they are adjacent and share the shift. */
static int add_range(neighbour *out, int m, int32_t j0, int32_t j1, double shx, double shy)
{
    if (j0 >= j1)
        return m;
    if (m > 0 && out[m - 1].j1 == j0 && out[m - 1].shift[0] == shx && out[m - 1].shift[1] == shy) {
        out[m - 1].j1 = j1;
        return m;
    }
    FS_ASSERT(m < MAX_RANGES);
    out[m].j0 = j0;
    out[m].j1 = j1;
    out[m].shift[0] = shx;
    out[m].shift[1] = shy;
    return m + 1;
}

/* Floor division of j by dim > 0. */
static int32_t floor_div(int32_t j, int32_t dim) { return j >= 0 ? j / dim : -((-j + dim - 1) / dim); }

/* 2-D: appends the particles of cells x0..x1 (unwrapped column indices) of grid row jy, whose image
 * is shifted by shy: one range per periodic image of the row, none outside a non-periodic side. */
static int add_span(const relax_state *s, neighbour *out, int m, int32_t jy, double shy, int32_t x0, int32_t x1)
{
    int32_t nx = s->dim[0], row = jy * nx;
    if (!s->per[0]) {
        x0 = x0 < 0 ? 0 : x0;
        x1 = x1 >= nx ? nx - 1 : x1;
        if (x0 > x1)
            return m;
        return add_range(out, m, s->start[row + x0], s->start[row + x1 + 1], 0.0, shy);
    }
    while (x0 <= x1) {
        int32_t w = floor_div(x0, nx);
        int32_t end = (w + 1) * nx - 1;
        if (end > x1)
            end = x1;
        m = add_range(out, m, s->start[row + x0 - w * nx], s->start[row + end - w * nx + 1],
                      (double)w * s->ext[0], shy);
        x0 = end + 1;
    }
    return m;
}

/* 2-D half stencil of cell (ix, iy), after slot 0 (the own cell): the cell to its right
 * and the three cells of the row above. With the particles after k in k's own cell, every pair of
 * periodic images within reach is visited exactly once, from one of its two ends. */
static int half_stencil_2d(const relax_state *s, int32_t ix, int32_t iy, neighbour *out)
{
    int m = add_span(s, out, 1, iy, 0.0, ix + 1, ix + 1);
    int32_t jy = iy + 1;
    double shy = 0.0;
    if (jy >= s->dim[1]) {
        if (!s->per[1])
            return m;
        jy -= s->dim[1];
        shy = s->ext[1];
    }
    return add_span(s, out, m, jy, shy, ix - 1, ix + 1);
}

/* Sphere half stencil of the cell (ix, iy, iz) with bucket b, after slot 0 (the own cell):
 * the neighbouring cells with a larger bucket (each pair of cells is then visited once). */
static int half_stencil_3d(const relax_state *s, int32_t ix, int32_t iy, int32_t iz, int32_t b, neighbour *out)
{
    int m = 1;
    for (int32_t jy = iy - 1; jy <= iy + 1; jy++) {
        if (jy < 0 || jy >= s->dim[1])
            continue;
        for (int32_t jx = ix - 1; jx <= ix + 1; jx++) {
            if (jx < 0 || jx >= s->dim[0])
                continue;
            const shell_column *c = &s->col[(size_t)jy * (size_t)s->dim[0] + (size_t)jx];
            int32_t base = c->base;
            for (int q = 0; q < 2; q++) {
                int32_t z0 = iz - 1 > c->lo[q] ? iz - 1 : c->lo[q];
                int32_t z1 = iz + 1 < c->lo[q] + c->count[q] - 1 ? iz + 1 : c->lo[q] + c->count[q] - 1;
                int32_t b0 = base + z0 - c->lo[q], b1 = base + z1 - c->lo[q];
                base += c->count[q];
                if (b0 <= b)
                    b0 = b + 1;
                if (b0 > b1)
                    continue;
                m = add_range(out, m, s->start[b0], s->start[b1 + 1], 0.0, 0.0);
            }
        }
    }
    return m;
}

/* Candidate pairs found in range, gathered without a branch on the distance (most candidates are
 * out of range and that branch would be unpredictable), so that only real pairs pay for the square
 * root and the division. */
#define HIT_CHUNK 64
typedef struct {
    int32_t j[HIT_CHUNK];
    double d[3][HIT_CHUNK];
} hit_list;

/* Two particles on the same spot (two snapped into one corner) have no direction between them:
 * the one with the larger index is pushed one way along the diagonal, the other the other way.
 * Returns the push on snapshot particle k by snapshot particle j, along each axis. */
static double coincident_push(const relax_state *s, int32_t k, int32_t j)
{
    return s->sid[k] > s->sid[j] ? 0.5 : -0.5;
}

/* Appends a force on snapshot particle j to a task's log. */
static void log_force(relax_task *task, int32_t j, const double *v)
{
    FS_ARRAY_RESERVE(task->log, task->cap_log, task->n_log + 1, 1024);
    force_entry *e = &task->log[task->n_log++];
    e->j = j;
    for (int a = 0; a < 3; a++)
        e->v[a] = v[a];
}

/* Adds the forces of the first c gathered pairs to particle k and, reversed, to their partners
 * (never k itself: the half stencil starts after k in its own cell, and k's periodic images are not
 * at distance 0). The force magnitude is 1 - (d / rsum)^2 along the line between the two. A force
 * on a particle before task->log_below is logged instead (as the negated term: x - y is x + (-y)). */
static inline void pair_forces(relax_task *task, const hit_list *h, int c, int32_t k, int dims)
{
    relax_state *s = task->s;
    double fk[3] = {0.0, 0.0, 0.0};
    for (int q = 0; q < c; q++) {
        int32_t j = h->j[q];
        double d2 = h->d[0][q] * h->d[0][q] + h->d[1][q] * h->d[1][q];
        if (dims == 3)
            d2 += h->d[2][q] * h->d[2][q];
        double rs = s->sr[k] + s->sr[j];
        double g, push = 0.0;
        if (d2 > 0.0) {
            double rs2 = rs * rs;
            g = (rs2 - d2) / (rs2 * sqrt(d2));
        } else {
            g = 0.0;
            push = coincident_push(s, k, j);
        }
        double fa[3] = {0.0, 0.0, 0.0};
        for (int a = 0; a < dims; a++) {
            fa[a] = g * h->d[a][q] + push;
            fk[a] += fa[a];
        }
        if (j >= task->log_below) {
            for (int a = 0; a < dims; a++)
                s->f[a][j] -= fa[a];
        } else {
            double neg[3] = {-fa[0], -fa[1], -fa[2]};
            log_force(task, j, neg);
        }
    }
    if (k >= task->log_below) {
        for (int a = 0; a < dims; a++)
            s->f[a][k] += fk[a];
    } else {
        log_force(task, k, fk);
    }
}

/* Adds the forces between particle k and the particles of ranges nb[0..m). */
static inline void particle_forces(relax_task *task, int32_t k, const neighbour *nb, int m, int dims)
{
    hit_list hit;
    const relax_state *s = task->s;
    const double *sx = s->sx[0], *sy = s->sx[1], *sz = s->sx[2], *sr = s->sr;
    double xi = sx[k], yi = sy[k], zi = dims == 3 ? sz[k] : 0.0, ri = sr[k];
    int c = 0;
    for (int q = 0; q < m; q++) {
        double cx = xi - nb[q].shift[0], cy = yi - nb[q].shift[1];
        for (int32_t j = nb[q].j0; j < nb[q].j1; j++) {
            double dx = cx - sx[j], dy = cy - sy[j];
            double d2 = dx * dx + dy * dy;
            hit.j[c] = j;
            hit.d[0][c] = dx;
            hit.d[1][c] = dy;
            if (dims == 3) {
                double dz = zi - sz[j];
                d2 += dz * dz;
                hit.d[2][c] = dz;
            }
            double rs = ri + sr[j];
            c += d2 < rs * rs;
            if (c == HIT_CHUNK) {
                pair_forces(task, &hit, c, k, dims);
                c = 0;
            }
        }
    }
    pair_forces(task, &hit, c, k, dims);
}

/* The same, specialised for 2-D and 3-D (dims a constant in the inner loops). */
static void particle_forces_2d(relax_task *task, int32_t k, const neighbour *nb, int m)
{
    particle_forces(task, k, nb, m, 2);
}

static void particle_forces_3d(relax_task *task, int32_t k, const neighbour *nb, int m)
{
    particle_forces(task, k, nb, m, 3);
}

/* The first bucket of grid row iy (iy = dim[1]: the number of buckets). */
static int32_t row_bucket(const relax_state *s, int32_t iy)
{
    if (iy >= s->dim[1])
        return s->n_buckets;
    return s->sphere ? s->col[(size_t)iy * (size_t)s->dim[0]].base : iy * s->dim[0];
}

/* Forces from the cells of rows [row0, row1), cell by cell in bucket order. */
static void row_forces(void *tasks, int32_t item)
{
    relax_task *task = (relax_task *)tasks + item;
    relax_state *s = task->s;
    neighbour nb[MAX_RANGES];
    int32_t b = row_bucket(s, task->row0);
    for (int32_t iy = task->row0; iy < task->row1; iy++)
        for (int32_t ix = 0; ix < s->dim[0]; ix++) {
            int runs = 1;
            const shell_column *col = NULL;
            if (s->sphere) {
                col = &s->col[(size_t)iy * (size_t)s->dim[0] + (size_t)ix];
                runs = 2;
            }
            for (int q = 0; q < runs; q++) {
                int32_t cells = s->sphere ? col->count[q] : 1;
                for (int32_t t = 0; t < cells; t++, b++) {
                    int32_t k0 = s->start[b], k1 = s->start[b + 1];
                    if (k0 == k1)
                        continue;
                    /* slot 0: the own cell (trimmed per particle below); the next cell in bucket
                     * order usually follows it in memory and merges into it */
                    nb[0].j0 = k0;
                    nb[0].j1 = k1;
                    nb[0].shift[0] = nb[0].shift[1] = 0.0;
                    int m = s->sphere ? half_stencil_3d(s, ix, iy, col->lo[q] + t, b, nb)
                                      : half_stencil_2d(s, ix, iy, nb);
                    for (int32_t k = k0; k < k1; k++) {
                        nb[0].j0 = k + 1;
                        if (s->sphere)
                            particle_forces_3d(task, k, nb, m);
                        else
                            particle_forces_2d(task, k, nb, m);
                    }
                }
            }
        }
    FS_ASSERT(b == row_bucket(s, task->row1));
}

/* design: forces on every particle of the snapshot (cleared by bucket_sort), summed in the order of
 * one sequential pass over the cells in bucket order, whatever the thread count. The grid rows are
 * cut into bands of about equal particle counts, one task each (BANDS_PER_THREAD). A row's half stencil reaches only
 * its own row and the row above (the top row wraps to row 0 when y is periodic), so the particles
 * of a band's first row also get forces from the band below, which come first in the sequential
 * order, and row 0 gets forces from the top band, which come last. Each band but the first logs its
 * forces on particles up to the end of its first row (row 0 included) instead of adding them, and
 * the logs are replayed band by band after all bands are done; every other particle gets forces
 * from one band only. So no two tasks write one particle, and every sum is added up in the same
 * order as in one pass. */
static void all_forces(relax_state *s)
{
    relax_task task[MAX_BANDS];
    int32_t rows[MAX_BANDS + 1];
    int bands = s->nthreads > 1 ? BANDS_PER_THREAD * s->nthreads : 1;
    int nt = 0;
    rows[0] = 0;
    for (int t = 1; t < bands; t++) {
        int32_t target = (int32_t)((int64_t)s->n * t / bands);
        int32_t r = rows[nt] + 1;
        while (r < s->dim[1] && s->start[row_bucket(s, r)] < target)
            r++;
        if (r >= s->dim[1])
            break;
        rows[++nt] = r;
    }
    rows[++nt] = s->dim[1];
    for (int t = 0; t < nt; t++) {
        memset(&task[t], 0, sizeof task[t]);
        task[t].s = s;
        task[t].t = t;
        task[t].row0 = rows[t];
        task[t].row1 = rows[t + 1];
        task[t].log_below = t == 0 ? 0 : s->start[row_bucket(s, rows[t] + 1)];
    }
    fs_parallel_for(nt, s->nthreads, row_forces, task);
    int dims = s->sphere ? 3 : 2;
    for (int t = 1; t < nt; t++) {
        for (int32_t e = 0; e < task[t].n_log; e++) {
            const force_entry *fe = &task[t].log[e];
            for (int a = 0; a < dims; a++)
                s->f[a][fe->j] += fe->v[a];
        }
        free(task[t].log);
    }
}

/* Moves a coordinate by dv: wraps on a periodic side, snaps to a non-periodic one. */
static double move_coord(double v, double dv, double ext, bool periodic)
{
    v += dv;
    if (periodic) {
        if (v < 0.0)
            v += ext;
        else if (v >= ext)
            v -= ext;
        if (v < 0.0 || v >= ext)
            v -= floor(v / ext) * ext;
        return (v >= ext || v < 0.0) ? 0.0 : v;
    }
    return v < 0.0 ? 0.0 : (v > ext ? ext : v);
}

/* Moves the particles of a task's range by step * force, capped at maxmove, back into the domain. */
static void move_particles(void *tasks, int32_t item)
{
    relax_task *task = (relax_task *)tasks + item;
    relax_state *s = task->s;
    int dims = s->sphere ? 3 : 2;
    double step = task->step, maxmove = task->maxmove;
    for (int32_t k = task->i0; k < task->i1; k++) {
        double mv[3] = {0.0, 0.0, 0.0}, l2 = 0.0;
        for (int a = 0; a < dims; a++) {
            mv[a] = step * s->f[a][k];
            l2 += mv[a] * mv[a];
        }
        double cap = l2 > maxmove * maxmove ? maxmove / sqrt(l2) : 1.0;
        if (s->sphere) {
            double p[3];
            for (int a = 0; a < 3; a++)
                p[a] = s->sx[a][k] + cap * mv[a];
            double len = fs_norm3(p);
            double kf = len > 0.0 ? s->radius / len : 1.0;
            for (int a = 0; a < 3; a++)
                s->x[a][k] = p[a] * kf;
        } else {
            for (int a = 0; a < 2; a++)
                s->x[a][k] = move_coord(s->sx[a][k], cap * mv[a], s->ext[a], s->per[a]);
        }
        s->r[k] = s->sr[k];
        s->id[k] = s->sid[k];
    }
}

/* One Jacobi iteration: forces from the snapshot, then every particle moves by step * force, capped
 * at maxmove, and is brought back into the domain. */
static void relax_step(relax_state *s, double step, double maxmove)
{
    relax_task task[MAX_THREADS];
    all_forces(s);
    particle_tasks(s, task);
    for (int t = 0; t < s->nthreads; t++) {
        task[t].step = step;
        task[t].maxmove = maxmove;
    }
    fs_parallel_for(s->nthreads, s->nthreads, move_particles, task);
}

/* Most cells of a grid of n points: a few per point. Cells at least dmax wide can be far more when
 * the domain is extremely elongated, or so small that dmax underflows; wider cells only put more
 * pairs in a cell, never miss a neighbour, so the count is capped instead. */
static int64_t grid_cell_budget(int32_t n)
{
    return 4 * (int64_t)n + 64;
}

/* Cells across a side of extent ext: as many as fit at least dmax wide, at least 1, at most `most`. */
static int32_t cells_along(double ext, double dmax, int64_t most)
{
    double m = floor(ext / dmax);
    if (!(m >= 1.0))
        return 1;
    return m > (double)most ? (int32_t)most : (int32_t)m;
}

/* 2-D grid: cells at least dmax wide (unless capped), a whole number of them across each side. */
static void setup_grid_2d(relax_state *s, double dmax)
{
    int64_t budget = grid_cell_budget(s->n);
    s->dim[0] = cells_along(s->ext[0], dmax, budget);
    s->dim[1] = cells_along(s->ext[1], dmax, budget / s->dim[0]);
    s->dim[2] = 1;
    s->inv_cell = s->dim[0] / s->ext[0];
    s->inv_cell_y = s->dim[1] / s->ext[1];
    s->origin = 0.0;
    s->n_buckets = s->dim[0] * s->dim[1];
}

/* Sphere grid: the cube [-R, R]^3 in cells at least dmax wide (at most the cell budget of columns);
 * per column, the runs of cells the sphere passes through (from the range of distances of the column
 * to the z axis), widened by a small margin against rounding. */
static void setup_grid_sphere(relax_state *s, double dmax)
{
    double R = s->radius, side = 2.0 * R;
    int32_t m = cells_along(side, dmax, (int64_t)floor(sqrt((double)grid_cell_budget(s->n))));
    double c = side / m, eps = 1e-6 * c;
    s->dim[0] = s->dim[1] = s->dim[2] = m;
    s->inv_cell = m / side;
    s->origin = -R;
    s->col = fs_malloc((size_t)m * (size_t)m * sizeof *s->col);
    int64_t total = 0;
    for (int32_t iy = 0; iy < m; iy++)
        for (int32_t ix = 0; ix < m; ix++) {
            double lo[2] = {-R + ix * c, -R + iy * c};
            double near2 = 0.0, far2 = 0.0;
            for (int a = 0; a < 2; a++) {
                double hi = lo[a] + c;
                double nearest = lo[a] > 0.0 ? lo[a] : (hi < 0.0 ? -hi : 0.0);
                double farthest = fmax(fabs(lo[a]), fabs(hi));
                near2 += nearest * nearest;
                far2 += farthest * farthest;
            }
            double rmin = sqrt(near2) - eps, rmax = sqrt(far2) + eps;
            shell_column *col = &s->col[(size_t)iy * (size_t)m + (size_t)ix];
            col->base = (int32_t)total;
            col->lo[0] = col->lo[1] = 0;
            col->count[0] = col->count[1] = 0;
            if (rmin > R)
                continue;
            double zout = sqrt(fmax(0.0, R * R - fmax(rmin, 0.0) * fmax(rmin, 0.0))) + eps;
            double zin = fmax(0.0, sqrt(fmax(0.0, R * R - rmax * rmax)) - eps);
            int32_t up0 = cell_coord(zin, s->origin, s->inv_cell, m), up1 = cell_coord(zout, s->origin, s->inv_cell, m);
            int32_t dn0 = cell_coord(-zout, s->origin, s->inv_cell, m), dn1 = cell_coord(-zin, s->origin, s->inv_cell, m);
            if (dn1 + 1 >= up0) {
                col->lo[0] = dn0;
                col->count[0] = up1 - dn0 + 1;
            } else {
                col->lo[0] = dn0;
                col->count[0] = dn1 - dn0 + 1;
                col->lo[1] = up0;
                col->count[1] = up1 - up0 + 1;
            }
            total += col->count[0] + col->count[1];
        }
    FS_ASSERT(total < INT32_MAX);
    s->n_buckets = (int32_t)total;
}

static void free_state(relax_state *s)
{
    for (int a = 0; a < 3; a++) {
        free(s->x[a]);
        free(s->sx[a]);
        free(s->f[a]);
    }
    free(s->r);
    free(s->id);
    free(s->key);
    free(s->sr);
    free(s->sid);
    free(s->start);
    free(s->tcount);
    free(s->col);
}

int fs_sample_repulsion(const fs_domain *domain, const fs_sample_params *params, fs_points *out)
{
    out->n = 0;
    out->p = NULL;
    if (check_count("sample", params->count) < 0 || check_domain("sample", domain) < 0)
        return -1;
    if (params->iterations < 0) {
        fs_error(FS_ERR_DATA, "sample: iterations must be 0 or more, got %d", params->iterations);
        return -1;
    }
    if (!(params->radius_jitter >= 0.0 && params->radius_jitter < 1.0)) {
        fs_error(FS_ERR_DATA, "sample: radius jitter must be in [0, 1), got %g", params->radius_jitter);
        return -1;
    }
    fs_domain d = *domain;
    fs_domain_normalize(&d);

    relax_state s;
    memset(&s, 0, sizeof s);
    int32_t n = params->count;
    uint64_t seed = params->seed;
    s.n = n;
    s.sphere = d.type == FS_DOMAIN_SPHERE;
    s.per[0] = d.periodic_x;
    s.per[1] = d.periodic_y;
    s.ext[0] = fs_domain_extent_x(&d);
    s.ext[1] = fs_domain_extent_y(&d);
    s.radius = d.radius;
    s.spacing = fs_sample_spacing(&d, n);
    int dims = s.sphere ? 3 : 2;

    for (int a = 0; a < dims; a++) {
        s.x[a] = fs_malloc((size_t)n * sizeof(double));
        s.sx[a] = fs_malloc((size_t)n * sizeof(double));
        s.f[a] = fs_malloc((size_t)n * sizeof(double));
    }
    s.r = fs_malloc((size_t)n * sizeof *s.r);
    s.sr = fs_malloc((size_t)n * sizeof *s.sr);
    s.id = fs_malloc((size_t)n * sizeof *s.id);
    s.key = fs_malloc((size_t)n * sizeof *s.key);
    s.sid = fs_malloc((size_t)n * sizeof *s.sid);

    double r0 = 0.5 * RSUM_OVER_SPACING * s.spacing;
    double jitter = params->radius_jitter;
    for (int32_t i = 0; i < n; i++) {
        double u0 = fs_rand01(seed, FS_RNG_SAMPLE_INIT, (uint64_t)i * 3 + 0);
        double u1 = fs_rand01(seed, FS_RNG_SAMPLE_INIT, (uint64_t)i * 3 + 1);
        if (s.sphere) {
            double z = s.radius * (2.0 * u0 - 1.0);
            double rho = sqrt(fmax(0.0, s.radius * s.radius - z * z));
            double phi = 2.0 * FS_PI * u1;
            s.x[0][i] = rho * cos(phi);
            s.x[1][i] = rho * sin(phi);
            s.x[2][i] = z;
        } else {
            s.x[0][i] = s.ext[0] * u0;
            s.x[1][i] = s.ext[1] * u1;
        }
        double u = fs_rand01(seed, FS_RNG_SAMPLE_RADIUS, (uint64_t)i);
        s.r[i] = r0 * (1.0 + jitter * (2.0 * u - 1.0));
        s.id[i] = i;
    }
    double dmax = 2.0 * r0 * (1.0 + jitter);
    if (s.sphere)
        setup_grid_sphere(&s, dmax);
    else
        setup_grid_2d(&s, dmax);
    s.start = fs_malloc(((size_t)s.n_buckets + 1) * sizeof *s.start);
    int budget = n >= PARALLEL_MIN_COUNT ? fs_threads() : 1;
    s.nthreads = budget > MAX_THREADS ? MAX_THREADS : budget;
    s.tcount = fs_malloc((size_t)s.nthreads * (size_t)s.n_buckets * sizeof *s.tcount);

    int iters = params->iterations;
    for (int it = 0; it < iters; it++) {
        double t = iters > 1 ? (double)it / (double)(iters - 1) : 0.0;
        double damp = 1.0 - (1.0 - DAMP_END) * t;
        bucket_sort(&s);
        relax_step(&s, STEP0 * damp * s.spacing, MAXMOVE0 * damp * s.spacing);
    }

    /* Points come out in the order of the last bucket sort (grid cells row by row): spatially
     * coherent, which makes the Delaunay triangulation and the mesh passes after it cache-friendly. */
    bucket_sort(&s);
    out->p = fs_malloc((size_t)n * 3 * sizeof(double));
    out->n = n;
    for (int32_t k = 0; k < n; k++) {
        double *p = out->p + 3 * (size_t)k;
        p[0] = s.sx[0][k];
        p[1] = s.sx[1][k];
        p[2] = s.sphere ? s.sx[2][k] : 0.0;
    }
    free_state(&s);
    return 0;
}

/* design: rows of points a apart along x, rows h = a sqrt(3)/2 apart, odd rows shifted by a/2, so
 * each point has six neighbours at distance a. A periodic side takes a whole number of columns (x) or
 * an even number of rows (y), so the lattice closes up across it; with one periodic side the other
 * follows isotropically, with both the row height is fitted on its own (slightly anisotropic: two
 * neighbours at a, four at sqrt(a^2/4 + h^2)). A non-periodic side is centred in the rectangle. */
int fs_sample_hex(const fs_domain *domain, int32_t count, fs_points *out)
{
    out->n = 0;
    out->p = NULL;
    if (check_count("hex lattice", count) < 0 || check_domain("hex lattice", domain) < 0)
        return -1;
    if (domain->type == FS_DOMAIN_SPHERE) {
        fs_error(FS_ERR_DATA, "hex lattice: expected a plane or cylinder domain");
        return -1;
    }
    fs_domain d = *domain;
    fs_domain_normalize(&d);
    double W = fs_domain_extent_x(&d), H = fs_domain_extent_y(&d);
    double a = fs_sample_spacing(&d, count);
    double h = a * sqrt(3.0) / 2.0;
    double nxd = 0.0, nyd = 0.0;
    if (d.periodic_x) {
        nxd = fmax(3.0, round(W / a));
        a = W / nxd;
        h = a * sqrt(3.0) / 2.0;
    }
    if (d.periodic_y) {
        nyd = fmax(4.0, 2.0 * round(H / (2.0 * h)));
        h = H / nyd;
        if (!d.periodic_x)
            a = 2.0 * h / sqrt(3.0);
    }
    if (!d.periodic_x)
        nxd = fmax(1.0, floor((W - 0.5 * a) / a) + 1.0);
    if (!d.periodic_y)
        nyd = fmax(1.0, floor(H / h) + 1.0);
    if (nxd * nyd > (double)SAMPLE_MAX_COUNT) {
        fs_error(FS_ERR_DATA, "hex lattice: %.0f points exceed the limit of %d", nxd * nyd, SAMPLE_MAX_COUNT);
        return -1;
    }
    int32_t nx = (int32_t)nxd, ny = (int32_t)nyd;
    double x0 = d.periodic_x ? 0.0 : fmax(0.0, 0.5 * (W - ((double)nx - 0.5) * a));
    double y0 = d.periodic_y ? 0.0 : fmax(0.0, 0.5 * (H - (double)(ny - 1) * h));

    out->n = nx * ny;
    out->p = fs_malloc((size_t)out->n * 3 * sizeof(double));
    for (int32_t j = 0; j < ny; j++)
        for (int32_t i = 0; i < nx; i++) {
            double *p = out->p + 3 * ((size_t)j * (size_t)nx + (size_t)i);
            p[0] = x0 + ((double)i + ((j & 1) ? 0.5 : 0.0)) * a;
            p[1] = y0 + (double)j * h;
            p[2] = 0.0;
        }
    return 0;
}
