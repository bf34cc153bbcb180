/* The wedge model's fracture loop: element selection, removal or subdivision (Algorithm 8), adaptive time steps to the next event (Algorithm 5), and the model interface. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "fracture/event.h"
#include "fracture/rank.h"
#include "geom/refine.h"
#include "model/wedge/internal.h"

/* Candidates of one subdivision batch, sorted by descending ratio, then ascending index. */
typedef struct {
    double ratio;
    int32_t e;
} candidate;

static int cmp_candidate(const void *a, const void *b)
{
    const candidate *x = a, *y = b;
    if (x->ratio != y->ratio)
        return x->ratio < y->ratio ? 1 : -1;
    return (x->e > y->e) - (x->e < y->e);
}

/* design: thesis Algorithm 8. The element that breaks is the one with the largest ratio of stress to
 * threshold (ties by the seed, fracture/rank.h). If it is not yet below mesh.min_size, it is subdivided
 * instead of removed, and the model relaxes again before anything breaks. Two departures, both for
 * the cost of re-analysing the sparse pattern after every change of the mesh: every other element over
 * its threshold and not below min_size is bisected in the same call, and the bisection goes on to the
 * descendants until all are below min_size (Algorithm 8 relaxes after each single bisection).
 * Subdivision refines the discretisation, not the material, and these elements sit where the next
 * fractures are about to happen, so the pattern is the same kind; one analysis replaces several. */
int fs_wedge_fracture(fs_wedge_model *w, int *removed)
{
    *removed = 0;
    if (!(fs_wedge_max_ratio(w) > 1.0))
        return 1;
    int32_t pick = fs_rank_pick(w->ratio, NULL, w->n_elems, w->cfg.seed);
    FS_ASSERT(pick >= 0);
    double min_size = w->cfg.mesh.min_size;
    if (fs_refine_tri_size(w->mesh, pick) >= min_size) {
        candidate *c = fs_malloc((size_t)w->n_elems * sizeof *c);
        int32_t n = 0;
        for (int32_t e = 0; e < w->n_elems; e++)
            if (w->state[e] == FS_WEDGE_ALIVE && w->ratio[e] > 1.0 && fs_refine_tri_size(w->mesh, e) >= min_size) {
                double r = fs_wedge_element_ratio(w, e);
                if (r > 1.0)
                    c[n++] = (candidate){r, e};
            }
        qsort(c, (size_t)n, sizeof *c, cmp_candidate);
        int32_t *list = fs_malloc((size_t)(n + 1) * sizeof *list);
        list[0] = pick;
        int32_t m = 1;
        for (int32_t q = 0; q < n; q++)
            if (c[q].e != pick)
                list[m++] = c[q].e;
        free(c);
        int32_t bisected = 0;
        int rc = fs_wedge_subdivide(w, list, m, true, &bisected);
        free(list);
        if (rc < 0)
            return -1;
        if (bisected > 0)
            return 0;
    }
    if (fs_wedge_remove(w, pick) < 0)
        return -1;
    *removed = 1;
    return 0;
}

/* The largest ratio the fracture method decides on: elements (removal) or split candidates. */
static double max_ratio(fs_wedge_model *w)
{
    return w->cfg.fracture.method == FS_FRACTURE_SPLIT ? fs_wedge_split_max_ratio(w) : fs_wedge_max_ratio(w);
}

/* The event search's view of the model (fracture/event.h, fs_event_find_estimated): the exact
 * equilibria it tried, as the bracket's ends. */
typedef struct {
    fs_wedge_model *w;
    fs_wedge_snapshot lo, hi;
} search_ctx;

static double exact_ratio(void *ctx, double t)
{
    search_ctx *c = ctx;
    if (fs_wedge_equilibrium(c->w, t) < 0)
        return NAN;
    double r = max_ratio(c->w);
    fs_wedge_snapshot_take(c->w, r > 1.0 ? &c->hi : &c->lo);
    return r;
}

static double estimated_ratio(void *ctx, double t)
{
    search_ctx *c = ctx;
    if (c->w->cfg.fracture.method == FS_FRACTURE_SPLIT)
        return fs_wedge_split_blend_ratio(c->w, &c->lo, &c->hi, t);
    if (fs_wedge_interpolate(c->w, &c->lo, &c->hi, t) < 0)
        return NAN;
    return max_ratio(c->w);
}

static void report(const fs_wedge_model *w, double t_end)
{
    fs_progress("wedge", t_end > 0.0 ? w->time / t_end : -1.0, "t = %.4g, %lld fractures, %d elements",
                w->time, (long long)w->fractures, (int)w->n_elems);
}

/* design: thesis Algorithm 1 with Algorithms 5 and 8. At the current time the model is relaxed; while
 * some element is over its threshold, one fracture event happens (removal or subdivision) and the
 * model relaxes again at the same time, so cracks run as far as the stresses drive them (after a
 * removal or a split, with solver.relax = local, by adaptive local relaxation, §5.8: fs_wedge_relax
 * finds the nodes the change unbalanced from the residual). With fracture.method = split the event
 * is fs_wedge_split_event and the ratio the nodal one of the split candidates. When nothing
 * is over its threshold, fs_event_find advances to just past the next time something is (within
 * time.min_step), starting with a step of half the time since the previous event. */
/* Adaptive refinement by von Mises discontinuity (thesis §5.7.7, Algorithm 13) after an equilibrium at
 * a new time, when mesh.refine_vm is set (wedge/tips.c). Returns 0 or -1. */
static int refine_at_new_time(fs_wedge_model *w)
{
    if (!(w->cfg.mesh.refine_vm > 0.0))
        return 0;
    return fs_wedge_refine_vm(w, w->cfg.mesh.refine_vm, w->cfg.mesh.refine_vm_rounds, NULL);
}

int fs_wedge_simulate(fs_wedge_model *w, double t_end)
{
    double min_step = w->cfg.time.min_step;
    if (fs_wedge_equilibrium(w, w->time) < 0 || refine_at_new_time(w) < 0)
        return -1;
    search_ctx search = {.w = w};
    const fs_event_fns fns = {exact_ratio, estimated_ratio};
    double last_event = w->time, dt_trial = fmax(min_step, (t_end - w->time) / 32.0);
    int rc = 0;
    for (;;) {
        while (max_ratio(w) > 1.0) {
            int removed = 0, changed = 1, tips = w->n_tips;
            bool split = w->cfg.fracture.method == FS_FRACTURE_SPLIT;
            double t_event = fs_seconds();
            rc = split ? fs_wedge_split_event(w, &changed) : fs_wedge_fracture(w, &removed);
            w->counters.event_seconds += fs_seconds() - t_event;
            if (rc < 0)
                goto done;
            if (rc == 1)
                break;
            if (!changed) {
                if (w->n_tips == tips)
                    break; /* nothing could be cut: let time advance */
                continue;  /* a tip was retired: the next candidate */
            }
            bool local = (removed || split) && w->cfg.solver.relax == FS_RELAX_LOCAL;
            double t0 = fs_seconds();
            rc = local ? fs_wedge_relax(w, NULL, 0) : fs_wedge_equilibrium(w, w->time);
            w->counters.event_relaxations++;
            w->counters.event_relax_seconds += fs_seconds() - t0;
            w->counters.event_seconds += fs_seconds() - t0;
            if (rc < 0)
                goto done;
            report(w, t_end);
        }
        rc = 0;
        if (w->time >= t_end)
            break;
        fs_event_result r;
        int last_exact;
        fs_wedge_snapshot_take(w, &search.lo);
        if ((rc = fs_event_find_estimated(&fns, &search, w->time, dt_trial, t_end, min_step, &r, &last_exact)) < 0)
            goto done;
        w->counters.time_steps++;
        w->counters.search_evaluations += r.evaluations;
        /* the exact equilibrium at r.t, unless the last call left the model there */
        if (r.found && !(last_exact && r.t_last == r.t)) {
            rc = search.hi.thickness == w->assembled_thickness ? fs_wedge_interpolate(w, &search.hi, &search.hi, r.t)
                                                                : fs_wedge_equilibrium(w, r.t);
            if (rc < 0)
                goto done;
        }
        if (r.found && (rc = refine_at_new_time(w)) < 0)
            goto done;
        report(w, t_end);
        if (!r.found)
            break;
        dt_trial = fmax(min_step, 0.5 * (r.t - last_event));
        last_event = r.t;
    }
done:
    fs_wedge_snapshot_free(&search.lo);
    fs_wedge_snapshot_free(&search.hi);
    return rc < 0 ? -1 : 0;
}

fs_wedge_model *fs_wedge_create(fs_mesh *mesh, const fs_model_setup *setup)
{
    fs_wedge_model *w = fs_malloc(sizeof *w);
    if (fs_wedge_init(w, mesh, setup) < 0) {
        free(w);
        return NULL;
    }
    return w;
}

int fs_wedge_advance(fs_wedge_model *w, double t) { return fs_wedge_simulate(w, t); }

fs_model_info fs_wedge_info(const fs_wedge_model *w) { return (fs_model_info){w->fractures, w->time}; }

void fs_wedge_report(const fs_wedge_model *w)
{
    const fs_wedge_counters *c = &w->counters;
    const fs_model_setup *cfg = &w->cfg;
    fs_debug("wedge: %lld splits, %lld tips retired by Griffith, %d tips left; relaxations %lld local, "
             "%lld global", (long long)w->fractures, (long long)w->griffith_stops, (int)w->n_tips,
             (long long)c->local_relaxations, (long long)c->global_fallbacks);
    double per = c->event_relaxations ? 1e3 / (double)c->event_relaxations : 0.0;
    fs_debug("wedge: %lld time steps, %lld event-search evaluations; %lld events with relaxation, %.2f ms each "
             "(%.2f ms relaxing); local relaxation %.2f s, %lld unknowns, %lld CG iterations, %lld retries",
             (long long)c->time_steps, (long long)c->search_evaluations, (long long)c->event_relaxations,
             per * c->event_seconds, per * c->event_relax_seconds, c->local_seconds, (long long)c->local_dofs,
             (long long)c->local_cg_iterations, (long long)c->relax_retries);
    fs_debug("wedge: %lld removals, %lld subdivisions, %lld solves (%.2f s), %lld factorizations (%.2f s), "
             "%lld analyses (%.2f s), %lld updates (%.2f s), assembly %.2f s, stresses %.2f s, "
             "%lld CG iterations",
             (long long)c->removals, (long long)c->subdivisions, (long long)c->solves, c->solve_seconds,
             (long long)c->factorizations, c->factor_seconds, (long long)c->analyses, c->analyze_seconds,
             (long long)c->updowns, c->update_seconds, c->assemble_seconds, c->stress_seconds,
             (long long)c->cg_iterations);
    if (cfg->mesh.refine_vm > 0.0)
        fs_debug("wedge: von Mises refinement: %lld rounds, %lld bisections, %.2f s", (long long)c->vm_rounds,
                 (long long)c->vm_bisections, c->vm_seconds);
    if (cfg->fracture.tip_submodel)
        fs_debug("wedge: tip sub-models: %lld, %.0f elements each, %lld found the tip below its threshold, "
                 "%.2f s (%.2f ms each)", (long long)c->submodels,
                 c->submodels ? (double)c->submodel_elements / (double)c->submodels : 0.0,
                 (long long)c->submodel_rejections, c->submodel_seconds,
                 c->submodels ? 1e3 * c->submodel_seconds / (double)c->submodels : 0.0);
    if (cfg->mesh.smooth_radius > 0.0)
        fs_debug("wedge: smoothing: %lld passes, %lld nodes moved, %.2f s", (long long)c->smoothings,
                 (long long)c->smoothed_nodes, c->smooth_seconds);
}

void fs_wedge_destroy(fs_wedge_model *w)
{
    if (!w)
        return;
    fs_wedge_free(w);
    free(w);
}
