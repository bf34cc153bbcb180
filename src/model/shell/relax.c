/* Local relaxation of the shell after cracks: only the nodes near the change move, the rest is held (thesis §5.8). */
#include "model/shell/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"

/* design: after a crack opens, only the nodes near it move much: the bond to the surface below
 * carries the released stress into the ground within a shear-lag length of the crack. So the nodes
 * within RINGS rings of edges of the changed nodes are relaxed with every other node held (a Newton
 * system over their DOFs and the energy of the triangles and bonds that depend on them, exact for
 * them), and the result is accepted when the largest residual force anywhere is below
 * solver.relax_tolerance of the force a crack releases on one edge (the threshold stress on a mean
 * edge's cross-section), as the wedge model's per-entry bound; else the region doubles, and past a
 * quarter of the nodes the whole shell is solved. The cascade of cuts at one time ends with a solve
 * of the whole shell (shell/fracture.c), which clears what the local ones left. */
#define RINGS 4

/* Appends to out[0..n) (marked) the nodes within rings rings of them (BFS over the triangles
 * around each node), marking them. Returns the new count. */
static int32_t grow(const fs_shell *s, int32_t *out, int32_t n, int rings, uint8_t *mark)
{
    const fs_mesh *m = s->mesh;
    int32_t start = 0;
    for (int r = 0; r < rings; r++) {
        int32_t end = n;
        for (int32_t q = start; q < end; q++) {
            int32_t v = out[q];
            for (int32_t k = m->ring_start[v]; k < m->ring_start[v + 1]; k++) {
                int32_t t = m->ring_tri[k];
                for (int c = 0; c < 3; c++) {
                    int32_t u = m->tri[3 * (size_t)t + c];
                    if (!mark[u]) {
                        mark[u] = 1;
                        out[n++] = u;
                    }
                }
            }
        }
        start = end;
    }
    return n;
}

/* The nodes within rings rings of the seeds, seeds first, marked. */
static int32_t region(const fs_shell *s, const int32_t *seeds, int32_t n_seeds, int rings, int32_t *out, uint8_t *mark)
{
    int32_t n = 0;
    for (int32_t q = 0; q < n_seeds; q++)
        if (!mark[seeds[q]]) {
            mark[seeds[q]] = 1;
            out[n++] = seeds[q];
        }
    return grow(s, out, n, rings, mark);
}

/* The triangles with a corner among the n nodes, then their neighbours (whose bending reads those
 * nodes across their edges), into s->local.tris; their marks are left set in s->local.in for
 * scope_clear. Returns their count. */
static int32_t scope_of(fs_shell *s, const int32_t *nodes, int32_t n)
{
    const fs_mesh *m = s->mesh;
    uint8_t *in = s->local.in;
    int32_t *tris = s->local.tris, nt = 0;
    for (int32_t q = 0; q < n; q++) {
        int32_t v = nodes[q];
        for (int32_t k = m->ring_start[v]; k < m->ring_start[v + 1]; k++) {
            int32_t t = m->ring_tri[k];
            if (!in[t]) {
                in[t] = 1;
                tris[nt++] = t;
            }
        }
    }
    int32_t core = nt;
    for (int32_t q = 0; q < core; q++)
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * (size_t)tris[q] + i];
            if (u >= 0 && !in[u]) {
                in[u] = 1;
                tris[nt++] = u;
            }
        }
    return nt;
}

static void scope_clear(fs_shell *s, int32_t nt)
{
    for (int32_t q = 0; q < nt; q++)
        s->local.in[s->local.tris[q]] = 0;
}

/* Relaxes the nodes of the region (n nodes) alone. Returns 0 or -1. */
static int relax_region(fs_shell *s, const int32_t *nodes, int32_t n)
{
    fs_shell_system sys;
    memset(&sys, 0, sizeof sys);
    sys.dof = s->local.dof; /* -1 everywhere between relaxations */
    int32_t nf = 0;
    for (int32_t q = 0; q < n; q++)
        for (int k = 0; k < 3; k++)
            if (s->sys.dof[3 * (size_t)nodes[q] + k] >= 0)
                sys.dof[3 * (size_t)nodes[q] + k] = nf++;
    sys.n_free = nf;
    sys.nodes = nodes;
    sys.n_nodes = n;
    sys.n_tris = scope_of(s, nodes, n);
    sys.tris = s->local.tris;
    int rc = nf > 0 ? fs_shell_solve(s, &sys) : 0;
    scope_clear(s, sys.n_tris);
    for (int32_t q = 0; q < n; q++)
        for (int k = 0; k < 3; k++)
            sys.dof[3 * (size_t)nodes[q] + k] = -1;
    sys.dof = NULL;
    sys.tris = NULL;
    sys.nodes = NULL;
    fs_shell_system_free(&sys);
    return rc;
}

/* The largest residual force on a free DOF after a relaxation of the region (n nodes, marked in
 * mark): nodes further than HALO rings from the region keep the forces they had, since nothing they
 * depend on (their triangles, and the hinges of these, reach two rings) moved; those were below the
 * tolerance when the last relaxation or equilibrium was accepted. So the forces are evaluated on
 * the region and its halo only, exactly (every triangle and hinge they depend on is in the scope).
 * nodes has room for every node; the halo is appended to it and unmarked again. */
#define HALO 2
static double region_residual(fs_shell *s, int32_t *nodes, int32_t n, uint8_t *mark)
{
    int32_t nh = grow(s, nodes, n, HALO, mark);
    fs_shell_system scope;
    memset(&scope, 0, sizeof scope);
    scope.dof = s->sys.dof;
    scope.nodes = nodes;
    scope.n_nodes = nh;
    scope.n_tris = scope_of(s, nodes, nh);
    scope.tris = s->local.tris;
    double *g = s->grad, rmax = 0.0;
    fs_shell_energy_in(s, &scope, s->x, g, false);
    scope_clear(s, scope.n_tris);
    for (int32_t q = 0; q < nh; q++) {
        size_t i = (size_t)nodes[q];
        for (int k = 0; k < 3; k++)
            if (s->sys.dof[3 * i + k] >= 0)
                rmax = fmax(rmax, fabs(g[3 * i + k]));
    }
    for (int32_t q = n; q < nh; q++)
        mark[nodes[q]] = 0;
    return rmax;
}

/* The scratch of the local relaxations, grown to the mesh (dof -1 and in 0 between uses). */
static void local_reserve(fs_shell *s)
{
    fs_shell_local *l = &s->local;
    if (l->cap_nodes < s->n_nodes) {
        l->dof = fs_realloc(l->dof, 3 * (size_t)s->cap_nodes * sizeof *l->dof);
        for (size_t k = 3 * (size_t)l->cap_nodes; k < 3 * (size_t)s->cap_nodes; k++)
            l->dof[k] = -1;
        l->cap_nodes = s->cap_nodes;
    }
    if (l->cap_tris < s->n_tris) {
        l->in = fs_realloc(l->in, (size_t)s->cap_tris);
        memset(l->in + l->cap_tris, 0, (size_t)(s->cap_tris - l->cap_tris));
        l->tris = fs_realloc(l->tris, (size_t)s->cap_tris * sizeof *l->tris);
        l->cap_tris = s->cap_tris;
    }
}

/* The force a crack releases on one edge: the mean threshold stress on a mean edge's cross-section
 * (MPa cm^2), the scale of the residuals a cut leaves. */
static double release_force(const fs_shell *s)
{
    double sum = 0.0, area = 0.0;
    for (int32_t t = 0; t < s->n_tris; t++) {
        sum += s->area0[t] * s->threshold[t] * fs_shell_tri_thickness(s, t);
        area += s->area0[t];
    }
    return area > 0.0 ? sum / area * s->unit : 1.0;
}

int fs_shell_relax(fs_shell *s, const int32_t *seeds, int32_t n_seeds)
{
    double t0 = fs_seconds();
    if (s->cfg.solver.relax == FS_RELAX_GLOBAL || n_seeds == 0) {
        int rc = fs_shell_equilibrium(s);
        s->counters.relax_seconds += fs_seconds() - t0;
        return rc;
    }
    double tol = s->cfg.solver.relax_tolerance * release_force(s);
    local_reserve(s);
    int32_t *nodes = fs_malloc(((size_t)s->n_nodes + 1) * sizeof *nodes);
    uint8_t *mark = fs_calloc((size_t)s->n_nodes + 1, 1);
    int rc = 1;
    for (int rings = RINGS; rc == 1 && rings <= 64; rings *= 2) {
        memset(mark, 0, (size_t)s->n_nodes);
        int32_t n = region(s, seeds, n_seeds, rings, nodes, mark);
        if (4 * n > s->n_nodes)
            break;
        if (relax_region(s, nodes, n) < 0) {
            fs_error_clear(); /* no local equilibrium: the whole shell below */
            break;
        }
        s->counters.local_relaxations++;
        s->counters.local_nodes += n;
        if (region_residual(s, nodes, n, mark) <= tol)
            rc = 0;
    }
    free(nodes);
    free(mark);
    if (rc == 1) { /* the change reaches far: the whole shell */
        s->counters.global_fallbacks++;
        rc = fs_shell_equilibrium(s);
    }
    s->counters.relax_seconds += fs_seconds() - t0;
    return rc;
}
