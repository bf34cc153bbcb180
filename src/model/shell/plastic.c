/* Shell plasticity: a von Mises yield surface on the strain with linear kinematic hardening, and its plastic update. */
#include "model/shell/internal.h"

#include <math.h>

/* design: Gingold et al. §"Plasticity" (after O'Brien et al. 2002): in 3-D the yield function is
 * Phi = |dev(eps_e) - gamma p| - eps0 on the elastic strain eps_e = eps - p with a traceless plastic
 * strain p, and a positive Phi is returned to zero along n = (dev(eps_e) - gamma p) / |...|. Their
 * shell formulas (the auxiliary strain A, F(E, P)) are scrambled in the extracted text and do not
 * read consistently, so they are derived here from the same assumptions:
 *  - plane stress: the elastic normal strain is -nu / (1 - nu) tr(eps_e); the plastic strain is
 *    stored in-plane (P, its normal component -tr P), per triangle for the membrane (Pm) and the
 *    bending (Pc) part, strain = m + z c through the thickness;
 *  - every point along the normal yields together, with the yield value averaged over the
 *    thickness: F^2 = |X_m|^2 + h^2 / 12 |X_c|^2, so the bending part enters scaled by h / sqrt(12);
 *  - X = dev(eps_e) - gamma p has in-plane part e - c1 tr(e) I - gamma P and normal part
 *    -c2 tr(e) + gamma tr(P), with c1 = (1 - 2 nu) / (3 (1 - nu)) and c2 = (1 + nu) / (3 (1 - nu))
 *    (their c = (1 + nu) / (6 (1 - nu)) is c2 / 2);
 *  - the update dP = mu n (in-plane part of n) at fixed total strain changes X by -mu D(n),
 *    D_in = (1 + gamma) n_in + c1 n_zz I, D_zz = (c2 + gamma) n_zz, and mu solves |X - mu D| = eps0
 *    (a quadratic; the smaller root), so the state is back on the yield surface, as their update
 *    intends.
 * eps0 comes from the von Mises yield stress: in uniaxial tension sigma_y = sqrt(6) G eps0. */

typedef struct {
    double in[3]; /* xx, yy, xy */
    double zz;
} tensor3;

static double norm2(const tensor3 *a)
{
    return a->in[0] * a->in[0] + a->in[1] * a->in[1] + 2.0 * a->in[2] * a->in[2] + a->zz * a->zz;
}

static double dot(const tensor3 *a, const tensor3 *b)
{
    return a->in[0] * b->in[0] + a->in[1] * b->in[1] + 2.0 * a->in[2] * b->in[2] + a->zz * b->zz;
}

/* X of an elastic strain e and plastic strain p (both in-plane). */
static tensor3 drive(const double e[3], const double p[3], double gamma, double c1, double c2)
{
    double tr = e[0] + e[1], trp = p[0] + p[1];
    tensor3 x = {{e[0] - c1 * tr - gamma * p[0], e[1] - c1 * tr - gamma * p[1], e[2] - gamma * p[2]},
                 -c2 * tr + gamma * trp};
    return x;
}

static tensor3 response(const tensor3 *n, double gamma, double c1, double c2)
{
    tensor3 d = {{(1.0 + gamma) * n->in[0] + c1 * n->zz, (1.0 + gamma) * n->in[1] + c1 * n->zz,
                  (1.0 + gamma) * n->in[2]},
                 (c2 + gamma) * n->zz};
    return d;
}

int32_t fs_shell_plastic_update(fs_shell *s, double *excess)
{
    double yield = 1e-3 * s->cfg.shell.yield; /* MPa */
    if (excess)
        *excess = 0.0;
    if (!(yield > 0.0))
        return 0;
    double nu = s->cfg.material.poisson, gamma = s->cfg.shell.hardening;
    double c1 = (1.0 - 2.0 * nu) / (3.0 * (1.0 - nu)), c2 = (1.0 + nu) / (3.0 * (1.0 - nu));
    fs_shell_update_phi(s, s->x, false);
    int32_t updated = 0;
    for (int32_t t = 0; t < s->n_tris; t++) {
        double em[3], ec[3];
        fs_shell_elastic_strains(s, s->x, t, em, ec);
        double h = fs_shell_tri_thickness(s, t), scale = h / sqrt(12.0);
        double eps0 = yield / (sqrt(6.0) * s->young[t] / (2.0 * (1.0 + nu)));
        double *pl = s->plastic + 6 * (size_t)t;
        double pm[3] = {pl[0], pl[1], pl[2]}, pc[3] = {pl[3] * scale, pl[4] * scale, pl[5] * scale};
        double ecs[3] = {ec[0] * scale, ec[1] * scale, ec[2] * scale};
        tensor3 xm = drive(em, pm, gamma, c1, c2), xc = drive(ecs, pc, gamma, c1, c2);
        double f2 = norm2(&xm) + norm2(&xc), f = sqrt(f2);
        if (!(f > eps0 * (1.0 + 1e-9)))
            continue;
        if (excess && f / eps0 - 1.0 > *excess)
            *excess = f / eps0 - 1.0;
        tensor3 nm = {{xm.in[0] / f, xm.in[1] / f, xm.in[2] / f}, xm.zz / f};
        tensor3 nc = {{xc.in[0] / f, xc.in[1] / f, xc.in[2] / f}, xc.zz / f};
        tensor3 dm = response(&nm, gamma, c1, c2), dc = response(&nc, gamma, c1, c2);
        double a = norm2(&dm) + norm2(&dc), b = dot(&xm, &dm) + dot(&xc, &dc), c = f2 - eps0 * eps0;
        double disc = b * b - a * c;
        double mu = (b - sqrt(disc > 0.0 ? disc : 0.0)) / a;
        for (int k = 0; k < 3; k++) {
            pl[k] += mu * nm.in[k];
            pl[3 + k] += mu * nc.in[k] / scale;
        }
        updated++;
    }
    s->counters.plastic_updates += updated;
    return updated;
}
