/* Background growth (velocity fields and their exact flow maps), its equivalent eigenstrain, and the layer's shrinkage and thickness over time. */
#ifndef FS_FIELD_GROWTH_H
#define FS_FIELD_GROWTH_H

#include "field/field.h"
#include "geom/domain.h"

/* Conventions.
 *
 * Units: time in the preset's time unit, lengths in cm, growth rates r1, r2 in 1/time unit, radius
 * rates in cm per time unit; strains are dimensionless.
 * Points and directions are in domain coordinates (geom/domain.h), three doubles:
 *   plane     (x, y, 0)
 *   cylinder  (s, z, 0), s = R * angle the unwrapped arc length around the trunk
 *   sphere    (x, y, z) in space, centred at the origin
 * Matrices are row-major: a 2x2 tensor m[2*i + j], a 3x3 one m[3*i + j].
 * 2-D Voigt order is (xx, yy, xy) with the engineering shear gamma_xy = 2 eps_xy, as in
 * model/wedge_element.h. "x" and "y" are the first two domain coordinates (s and z on the cylinder).
 *
 * design: the thesis (§3.3.1, Eq. 3.4) moves an attachment point along P(t) = P(0) + t v(P(0)), the
 * first-order step of its velocity field. Here the velocity field is integrated exactly instead, so
 * that flows compose (flow(t0 -> t1) then flow(t1 -> t2) is flow(t0 -> t2)) and a run does not
 * depend on its time steps:
 *   planar    v = G (p - p_fixed), G = R(alpha) diag(r1, r2) R(alpha)^T, flow p_fixed + exp(G dt) (p - p_fixed)
 *   cylinder  R(t) = R0 + rate t; a point keeps its angle and height, so s scales by R(t1) / R(t0)
 *   sphere    equatorial radius a(t) = R0 + rate t, polar (z) semi-axis c(t) = R0 + axis_ratio rate t;
 *             (x, y) scale by a(t1) / a(t0), z by c(t1) / c(t0)
 * The thesis' cylinder and sphere fields v = r (x, y, 0) and v = r (x, y, z) with its Eq. 3.4 give
 * R(t) = R0 (1 + r t): the same linear radius, with rate = r R0 here (cm per time unit, fs_growth).
 * All three flow maps are linear (affine for the plane) in domain coordinates, so the stretch of a
 * segment is exact for finite segments, and the growth is uniform: no point is special except the
 * planar fixed point and the seam s = 0 of the cylinder, which stays put (any other angle would do). */

/* The fixed point of planar growth, the one point of the background that does not move (thesis §3.3.1:
 * the constants C1, C2 of the planar velocity field). Kept apart from fs_growth until field.h gains
 * these two fields. */
typedef struct {
    double fixed_x;   /* first domain coordinate (cm) */
    double fixed_y;   /* second domain coordinate (cm) */
} fs_growth_fixed_point;

/* A growth field resolved against its domain: what the functions below evaluate. Plain data, no
 * ownership; copy freely. */
typedef struct {
    fs_growth_type type;
    double r1, r2;       /* planar: eigenvalues of the growth tensor (1/time unit) */
    double axis1[2];     /* planar: unit eigenvector of r1, (cos alpha, sin alpha) with alpha from the x axis */
    double fixed[2];     /* planar: the fixed point (domain coordinates, cm) */
    double radius0;      /* cylinder, sphere: radius at t = 0 (cm), the domain's radius */
    double rate;         /* cylinder: dR/dt; sphere: da/dt, of the equatorial radius (cm per time unit) */
    double rate_z;       /* sphere: dc/dt of the z semi-axis, axis_ratio * rate (cm per time unit) */
} fs_growth_field;

/* Resolves growth g on domain d for times in [0, time_end].
 *   type none      the background is static.
 *   type planar    plane or cylinder (on the cylinder, G acts on (s, z)). alpha = g->angle is the
 *                  direction of the r1 axis in degrees counter-clockwise from the x axis (the thesis
 *                  measures it from the y axis: thesis alpha = 90 - angle). fixed may be NULL: the
 *                  centre of the domain rectangle (fs_domain_extent_x / 2, fs_domain_extent_y / 2).
 *   type cylinder  cylinder domain; R(t) = d->radius + g->rate t.
 *   type sphere    sphere domain; a(t) = d->radius + g->rate t and c(t) = d->radius + g->axis_ratio
 *                  g->rate t. axis_ratio means: the z semi-axis grows axis_ratio times as fast, in cm
 *                  per time unit, as the equatorial radius (1 = isogonic; Fig. 5.32's elongated
 *                  sphere is 4). Both start at the domain radius, so at time t the background is the
 *                  spheroid x^2/a^2 + y^2/a^2 + z^2/c^2 = 1 (no longer fs_domain_wrap's sphere).
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) if the growth type does not suit the domain, a radius
 * is not positive at t = 0 or t = time_end, or time_end < 0. */
int fs_growth_field_init(fs_growth_field *f, const fs_growth *g, const fs_growth_fixed_point *fixed,
                         const fs_domain *d, double time_end);

/* The cylinder's radius R(t) (cylinder growth), the sphere's equatorial radius a(t) (sphere growth),
 * or radius0 (other types). The cylinder's unwrapped period at time t is 2 pi R(t). */
double fs_growth_radius(const fs_growth_field *f, double t);

/* The sphere's z semi-axis c(t); equal to fs_growth_radius for the other types. */
double fs_growth_radius_z(const fs_growth_field *f, double t);

/* The velocity v(p, t) of the background point at p at time t (cm per time unit). v[2] = 0 on the
 * plane and cylinder. */
void fs_growth_velocity(const fs_growth_field *f, const double p[3], double t, double v[3]);

/* The flow map: where the background point that was at p at time t0 is at time t1 (t1 < t0 runs
 * the growth backwards). out may alias p. Precondition (FS_ASSERT): t0 and t1 keep the radii
 * positive, which fs_growth_field_init guarantees for [0, time_end]. */
void fs_growth_flow(const fs_growth_field *f, const double p[3], double t0, double t1, double out[3]);

/* The Jacobian J = d flow / d p from t0 to t1 (3x3, the same at every point: the flow maps are
 * linear). Plane and cylinder: the in-plane 2x2 block F, J[8] = 1, zeros elsewhere. */
void fs_growth_jacobian(const fs_growth_field *f, double t0, double t1, double J[9]);

/* The stretch |J d| / |d| of a small background segment of direction d (domain coordinates, d[2] = 0
 * on the plane and cylinder, tangent to the sphere at p) that was at p at time t0, at time t1.
 * Exact for finite segments (the maps are linear); p does not change the result for these uniform
 * fields and is there so that spatially varying ones keep the call. Precondition: d != 0. */
double fs_growth_stretch(const fs_growth_field *f, const double p[3], const double d[3], double t0, double t1);

/* The relative elemental rate of growth at time t of a small segment whose direction at time t is d
 * (thesis Eq. 3.2: RERG = e . (grad v) e, e = d / |d|): the time derivative of the log of its
 * stretch (1/time unit). Precondition: d != 0. */
double fs_growth_rate_along(const fs_growth_field *f, const double p[3], const double d[3], double t);

/* The in-plane strain of the background from t0 to t1, for plane and cylinder domains (on the
 * sphere the strain varies from point to point: move the nodes with fs_growth_flow instead;
 * FS_ASSERT).
 * design: the measure is the Biot strain eps = F - I of the in-plane deformation gradient F (the 2x2
 * block of fs_growth_jacobian). F is symmetric for every field here (exp of a symmetric G, or a
 * diagonal scaling), so F is its own stretch tensor and there is no rotation to remove: along a
 * principal direction, eps is exactly stretch - 1, and to first order it is the small strain.
 * It is also what makes growth and eigenstrain exactly equivalent in linear elasticity: bottom nodes
 * moved by F load a bonded layer with the strain F - I; an unmoved layer with eigenstrain -(F - I) has
 * the same stress sigma = C (eps_total - eps*) (SPEC §4, thesis §4.3 and Fig. 4.5: isogonic growth of
 * the background and shrinkage of the layer give the same pattern). So on periodic domains the layer's
 * eigenstrain from growth is minus this strain; it adds to the shrinkage eigenstrain below to first
 * order.
 * eps (2x2 tensor) and voigt (xx, yy, engineering xy) may each be NULL. */
void fs_growth_strain(const fs_growth_field *f, double t0, double t1, double eps[4], double voigt[3]);

/* The isotropic shrinkage eigenstrain of the layer at time t: *top = -top(t), *bottom = -bottom(t)
 * (thesis §3.3.2: a shrinkage value s > 0 means the free material would shorten by the fraction s;
 * negative s swells it). Either output may be NULL. */
void fs_shrink_eigenstrain(const fs_shrink *s, double t, double *top, double *bottom);

/* The scale factors of a wedge's reference shape at time t (thesis §3.3.2, Fig. 3.10): scale[0] for
 * the bottom face triangle (1 - bottom(t)), scale[1] for the top face triangle (1 - top(t)), and
 * scale[2] for the height, shrunk by the average of the two, 1 - (top(t) + bottom(t)) / 2. */
void fs_shrink_scales(const fs_shrink *s, double t, double scale[3]);

/* Checks that no shrinkage value reaches 1 (the reference shape would collapse or turn inside out).
 * The functions are piecewise linear, so checking the knots suffices.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) naming the key ([shrink] top or bottom) and the knot. */
int fs_shrink_check(const fs_shrink *s);

/* The layer thickness at time t (cm): m->thickness at t <= 0, m->thickness_final at t >= time_end,
 * linear in between; constant m->thickness when m->thickness_final < 0 or time_end <= 0. */
double fs_material_thickness(const fs_material *m, double t, double time_end);

#endif
