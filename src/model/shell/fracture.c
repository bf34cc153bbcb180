/* The shell model's fracture criterion per face, the search in time for the next event, and the time loop. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/event.h"
#include "fracture/separation.h"

/* design: Gingold et al. §"Fracture": a face fails where a principal value of the strain
 * E(z) = Em + z Ec at z = +-h/2 passes a threshold. fissure's presets give the threshold as a stress
 * (kPa, as for the wedge model), so the criterion here is the largest principal plane stress at
 * z = +-h/2 of the elastic strains (E / (1 - nu^2) ((1 - nu) e + nu tr(e) I)) over the face's
 * threshold stress: tension only, the same measure the wedge model compares (the principal strain
 * of the paper times the plane-stress modulus, up to the nu coupling). The crack's plane is normal
 * to that principal direction.
 *
 * A bonded shell: the bond pulls on the layer's bottom face, so the layer shears through its
 * thickness and its faces do not strain alike. The bond's stiffness (shell.c: 2G/h per unit area
 * times [shell] bond b) is that of the lower half of the layer sheared uniformly, through the
 * half-thickness, from the surface's point to the middle surface's (b = 1: a bottom face held to the
 * surface; b < 1: a softer surface takes 1 - b of the shear). The same uniform shear carries on to
 * the free top face, whose displacement is then the middle surface's plus b times the middle
 * surface's displacement from the surface below, and whose membrane strain is
 *     Em + b (Em(x) - Em(anchors))            (b at most 1),
 * as in a wedge layer (linear through its thickness) on its bottom. Near a crack, where the middle
 * surface shrinks back from its anchors, the top face is relieved twice as much as the middle
 * (for b = 1): this is what spaces the cracks of a thin bonded layer at the wedge model's spacing
 * (tests/cli_shell.sh compares the two). The bottom face of a bonded shell is held by its bond, as
 * the wedge and tet models' bottoms are, and is not read; a free shell (b = 0) reads both faces. */

/* The bond's shear of the membrane strain of face t at the current positions (fracture.c design):
 * Em(x) - Em(anchors), in the face's frame. */
static void bond_shear(const fs_shell *s, int32_t t, double d[3])
{
    double ex[3], ea[3], unused[3];
    fs_shell_strains(s, s->x, t, ex, unused);
    fs_shell_strains(s, s->anchor, t, ea, unused);
    for (int k = 0; k < 3; k++)
        d[k] = ex[k] - ea[k];
}

/* The plane stress (xx, yy, xy in face t's rest frame) of the elastic strains at the side of t the
 * criterion reads that is the more loaded (see the design note), into plane, and its largest
 * principal stress, or NaN for a stress that is not finite; m (may be NULL) receives the principal
 * direction, in the frame. */
static double critical_stress(const fs_shell *s, int32_t t, double plane[3], double m[2])
{
    double em[3], ec[3];
    fs_shell_elastic_strains(s, s->x, t, em, ec);
    double h = fs_shell_tri_thickness(s, t), nu = s->cfg.material.poisson;
    double c = s->young[t] / (1.0 - nu * nu);
    double bond = fmin(s->cfg.shell.bond, 1.0);
    if (bond > 0.0) {
        double d[3];
        bond_shear(s, t, d);
        for (int k = 0; k < 3; k++)
            em[k] += bond * d[k];
    }
    double best = -INFINITY, dir[2] = {1.0, 0.0};
    plane[0] = plane[1] = plane[2] = 0.0;
    for (int side = bond > 0.0 ? 1 : -1; side <= 1; side += 2) {
        double z = 0.5 * h * side;
        double e[3] = {em[0] + z * ec[0], em[1] + z * ec[1], em[2] + z * ec[2]};
        double tr = e[0] + e[1];
        double stress[6] = {c * ((1.0 - nu) * e[0] + nu * tr), c * ((1.0 - nu) * e[1] + nu * tr), 0.0,
                            c * (1.0 - nu) * e[2], 0.0, 0.0};
        double sigma[3], dirs[9];
        if (fs_eigen_principal_stress(stress, sigma, dirs) < 0) {
            fs_error_clear();
            return NAN;
        }
        if (sigma[0] > best) {
            best = sigma[0];
            plane[0] = stress[0];
            plane[1] = stress[1];
            plane[2] = stress[3];
            double l = hypot(dirs[0], dirs[1]);
            if (l > 0.0) {
                dir[0] = dirs[0] / l;
                dir[1] = dirs[1] / l;
            }
        }
    }
    if (m) {
        m[0] = dir[0];
        m[1] = dir[1];
    }
    return best;
}

/* fs_shell_face_ratio, and when stress is not NULL the plane stress it reads as a 3-D Voigt stress. */
static double face_criterion(const fs_shell *s, int32_t t, double m[2], double stress[6])
{
    double plane[3], sigma1 = critical_stress(s, t, plane, m);
    if (stress && isfinite(sigma1))
        fs_plane_stress_voigt(s->frame + 6 * (size_t)t, s->frame + 6 * (size_t)t + 3, plane, stress);
    else if (stress)
        memset(stress, 0, 6 * sizeof *stress);
    return sigma1 / s->threshold[t];
}

double fs_shell_face_ratio(const fs_shell *s, int32_t t, double m[2])
{
    return face_criterion(s, t, m, NULL);
}

typedef struct {
    const fs_shell *s;
    double *ratio, *m, *stress;
} ratios_ctx;

static void ratios_range(void *ctx, int32_t t0, int32_t t1)
{
    const ratios_ctx *c = ctx;
    for (int32_t t = t0; t < t1; t++)
        c->ratio[t] = face_criterion(c->s, t, c->m ? c->m + 2 * (size_t)t : NULL,
                                     c->stress ? c->stress + 6 * (size_t)t : NULL);
}

void fs_shell_face_ratios(fs_shell *s, double *ratio, double *m, double *stress)
{
    fs_shell_update_phi(s, s->x, false);
    ratios_ctx c = {s, ratio, m, stress};
    fs_shell_parallel(s->n_tris, ratios_range, &c);
}

double fs_shell_max_ratio(fs_shell *s, double *ratio)
{
    double *r = ratio ? ratio : s->face_ratio, best = -INFINITY;
    fs_shell_face_ratios(s, r, NULL, NULL);
    for (int32_t t = 0; t < s->n_tris; t++)
        if (r[t] > best)
            best = r[t];
    return best;
}

/* ---- the search in time ---- */

/* The event search's view of the model (fracture/event.h, fs_event_find_estimated): the exact
 * equilibria it tried as the bracket's ends, and the state it started from with the rate of change
 * of the positions, for the starting guesses. */
typedef struct {
    fs_shell *s;
    double t0, *x0;            /* the accepted state the search starts from */
    double t_lo, *x_lo;        /* the latest exact state with ratio <= 1 */
    double t_hi, *x_hi;        /* the latest exact state with ratio > 1 */
    bool have_hi;
} search_ctx;

/* A starting guess for the equilibrium at t: the accepted state moved on by its rate. */
static void guess(const search_ctx *c, double t)
{
    fs_shell *s = c->s;
    size_t n = 3 * (size_t)s->n_nodes;
    for (size_t k = 0; k < n; k++)
        s->x[k] = c->x0[k] + (s->rate_valid ? (t - c->t0) * s->rate[k] : 0.0);
    /* held components stay where they are */
    for (int32_t i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++)
            if (s->sys.dof[3 * (size_t)i + k] < 0)
                s->x[3 * (size_t)i + k] = c->x0[3 * (size_t)i + k];
}

static double exact_ratio(void *ctx, double t)
{
    search_ctx *c = ctx;
    fs_shell *s = c->s;
    fs_shell_set_time(s, t);
    guess(c, t);
    s->counters.search_evaluations++;
    if (fs_shell_equilibrium(s) < 0)
        return NAN;
    double r = fs_shell_max_ratio(s, NULL);
    size_t n = 3 * (size_t)s->n_nodes;
    if (r > 1.0) {
        memcpy(c->x_hi, s->x, n * sizeof *s->x);
        c->t_hi = t;
        c->have_hi = true;
    } else {
        memcpy(c->x_lo, s->x, n * sizeof *s->x);
        c->t_lo = t;
    }
    return r;
}

/* The ratio of the state at t blended between the bracket's ends (positions linear in time between
 * two equilibria: exact for a linear shell, an estimate the search checks otherwise). */
static double estimated_ratio(void *ctx, double t)
{
    search_ctx *c = ctx;
    fs_shell *s = c->s;
    if (!c->have_hi || !(c->t_hi > c->t_lo))
        return exact_ratio(ctx, t);
    double w = (t - c->t_lo) / (c->t_hi - c->t_lo);
    size_t n = 3 * (size_t)s->n_nodes;
    for (size_t k = 0; k < n; k++)
        s->x[k] = c->x_lo[k] + w * (c->x_hi[k] - c->x_lo[k]);
    fs_shell_set_time(s, t);
    return fs_shell_max_ratio(s, NULL);
}

/* design: plasticity at each accepted time step: the plastic update (a return to the yield surface
 * at fixed positions) and the equilibrium alternate until no face is over yield by more than
 * PLASTIC_TOLERANCE of it (each round takes off about a third of the excess, so this takes some ten
 * rounds after a step that loads a face well past yield, and one when nothing flows). The cuts of a
 * cascade at one time are elastic: a crack runs much faster than the coat flows; the faces a
 * cascade left over yield flow at the next step. */
#define PLASTIC_TOLERANCE 1e-3
#define PLASTIC_ROUNDS 50

static int plastic_steps(fs_shell *s)
{
    if (!(s->cfg.shell.yield > 0.0))
        return 0;
    for (int round = 0; round < PLASTIC_ROUNDS; round++) {
        double excess;
        if (fs_shell_plastic_update(s, &excess) == 0)
            return 0;
        if (fs_shell_equilibrium(s) < 0)
            return -1;
        if (excess < PLASTIC_TOLERANCE)
            return 0;
    }
    return 0;
}

static void report(const fs_shell *s, double t_end)
{
    fs_progress("shell", t_end > 0.0 ? s->time / t_end : -1.0, "t = %.4g, %lld fractures, %d triangles", s->time,
                (long long)s->fractures, (int)s->n_tris);
}

/* Largest number of fracture events at one time before time must move on (a guard against a cascade
 * that does not end; cracks that run across the whole layer take far fewer). */
#define MAX_EVENTS_AT_ONCE 100000

/* design: Gingold et al.'s SimulationLoop, quasi-static: at the current time the shell is in
 * equilibrium; while some face is over its threshold, the faces over it fracture (a batch of faces
 * apart from each other, fs_shell_fracture_batch) and the shell returns to equilibrium at the same
 * time, so cracks run as far as the stresses drive them. Otherwise the search in time
 * (fs_event_find_estimated, the thesis' Algorithm 5 with blended states; it plays the role of their
 * 2^-k search) advances to just past the next time a face reaches its threshold (within
 * time.min_step), in steps of at most shell.max_step of the run; each accepted step updates the
 * plastic strain. */
int fs_shell_advance(fs_shell *s, double t_end)
{
    double min_step = s->cfg.time.min_step;
    double max_step = s->cfg.shell.max_step * s->cfg.time.end;
    size_t n = 3 * (size_t)s->n_nodes;
    search_ctx c = {.s = s};
    const fs_event_fns fns = {exact_ratio, estimated_ratio};
    double dt_trial = fmax(min_step, fmin(max_step, (t_end - s->time) / 32.0)), last_event = s->time;
    int rc = 0;
    for (;;) {
        /* the cascade at this time: cut and relax around the cut until nothing is over its threshold
         * (the local relaxations leave residuals below solver.relax_tolerance of a crack's force; the
         * next time step solves the whole shell) */
        for (int64_t events = 0; events < MAX_EVENTS_AT_ONCE;) {
            double t0 = fs_seconds();
            int32_t *seeds = NULL, n_seeds = 0;
            int32_t cuts = fs_shell_fracture_batch(s, &seeds, &n_seeds);
            s->counters.fracture_seconds += fs_seconds() - t0;
            if (cuts > 0 && fs_shell_relax(s, seeds, n_seeds) < 0)
                cuts = -1;
            free(seeds);
            if (cuts < 0) {
                rc = -1;
                goto done;
            }
            if (cuts == 0)
                break; /* nothing over its threshold, or nothing could be cut: let time move on */
            events += cuts;
            report(s, t_end);
        }
        if (s->time >= t_end)
            break;
        n = 3 * (size_t)s->n_nodes;
        c.x0 = fs_realloc(c.x0, n * sizeof *c.x0);
        c.x_lo = fs_realloc(c.x_lo, n * sizeof *c.x_lo);
        c.x_hi = fs_realloc(c.x_hi, n * sizeof *c.x_hi);
        memcpy(c.x0, s->x, n * sizeof *c.x0);
        memcpy(c.x_lo, s->x, n * sizeof *c.x_lo);
        c.t0 = c.t_lo = s->time;
        c.have_hi = false;
        double t_stop = fmin(t_end, s->time + max_step);
        if (t_end - t_stop < 1e-9 * max_step)
            t_stop = t_end;
        fs_event_result r;
        int last_exact;
        if (fs_event_find_estimated(&fns, &c, s->time, fmin(dt_trial, t_stop - s->time), t_stop, min_step, &r,
                                    &last_exact) < 0) {
            rc = -1;
            goto done;
        }
        /* the exact equilibrium at r.t, unless the last call left the shell there */
        if (!(last_exact && r.t_last == r.t)) {
            fs_shell_set_time(s, r.t);
            const double *from = r.found && c.have_hi ? c.x_hi : c.x_lo;
            memcpy(s->x, from, n * sizeof *s->x);
            if (fs_shell_equilibrium(s) < 0) {
                rc = -1;
                goto done;
            }
        }
        s->counters.steps++;
        /* the rate of the positions over the step, for the next guesses */
        double dt = r.t - c.t0;
        if (dt > 0.0) {
            for (size_t k = 0; k < n; k++)
                s->rate[k] = (s->x[k] - c.x0[k]) / dt;
            s->rate_valid = true;
        }
        if (plastic_steps(s) < 0) {
            rc = -1;
            goto done;
        }
        report(s, t_end);
        if (r.found) {
            dt_trial = fmax(min_step, 0.5 * (r.t - last_event));
            last_event = r.t;
        } else {
            dt_trial = fmax(dt_trial, min_step);
        }
    }
done:
    free(c.x0);
    free(c.x_lo);
    free(c.x_hi);
    return rc;
}
