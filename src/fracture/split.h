/* Element-plane split geometry in a node's tangent plane and the Griffith energy check, for any model that cuts elements. */
#ifndef FS_FRACTURE_SPLIT_H
#define FS_FRACTURE_SPLIT_H

#include <stdbool.h>

/* design: thesis §5.7.2-5.7.5 (Algorithms 10 and 12). A crack through a node n is a plane whose trace
 * in the surface is a line through n; seen from n, each element around n is a sector (n, a, b) of the
 * fan, and a ray from n in direction d leaves that sector through its opposite edge ab. These kernels
 * work in 2-D coordinates relative to n (the model projects onto n's tangent plane), so triangles
 * (shells, wedge columns) and the faces of tetrahedra can use them alike. */

/* Where a ray leaves a sector. */
typedef enum {
    FS_SPLIT_MISS = 0,  /* the ray does not pass through the sector */
    FS_SPLIT_EDGE,      /* it crosses the open edge ab at parameter *s in (snap, 1 - snap) */
    FS_SPLIT_AT_A,      /* it passes within the snap tolerance of a (*s <= snap) */
    FS_SPLIT_AT_B       /* it passes within the snap tolerance of b (*s >= 1 - snap) */
} fs_split_hit;

/* The ray n + t d (t > 0, n at the origin) against the sector (origin, a, b), counter-clockwise
 * (cross(a, b) > 0). The sector holds the ray when cross(a, d) >= 0 and cross(d, b) >= 0; then *s
 * receives the parameter of the crossing point a + s (b - a) of the line through a and b, and the
 * result says whether it is within snap (a fraction of the edge, 0 <= snap < 0.5) of an end. d need
 * not be unit. Returns FS_SPLIT_MISS (with *s = -1) for a degenerate sector or d = 0. */
fs_split_hit fs_split_ray_sector(const double a[2], const double b[2], const double d[2], double snap, double *s);

/* The crack direction (unit, in the plane) of a fracture plane with in-plane normal m (any length):
 * m turned by +90 degrees. Returns false (dir zeroed) when m is zero or not finite. */
bool fs_split_crack_direction(const double m[2], double dir[2]);

/* Of the rays +dir and -dir of a crack line, the one that continues a crack arriving along incoming
 * (the direction it travelled in): dir or -dir, whichever has the larger component along incoming
 * (dir itself on a tie). out may alias dir. */
void fs_split_continue_direction(const double dir[2], const double incoming[2], double out[2]);

/* Position of the point q after an edge collapse moves it onto the line through the origin along d
 * (unit): its orthogonal projection (Algorithm 12). */
void fs_split_project_onto_line(const double q[2], const double d[2], double out[2]);

/* Unit conversion of a fracture toughness (critical energy release rate) given in J/m^2 into the
 * models' units, MPa cm (1 MPa cm = 1e4 J/m^2). */
double fs_griffith_toughness_model_units(double toughness_j_per_m2);

/* design: thesis §5.7.4, Algorithm 11 (Griffith [20]). G = (e1 - e2) / a is the elastic strain energy
 * released per unit of new crack-wall area a, from the energies e1 before and e2 after the extension
 * (each after equilibrium). The crack extends while G > Gc; otherwise it is terminated. Energies in
 * MPa cm^3 (= J), area in cm^2, so G and gc are in MPa cm (fs_griffith_toughness_model_units).
 * Returns G, or NaN when a is not positive. */
double fs_griffith_release(double e1, double e2, double a);

/* true when the extension releases more than gc per unit area (G > gc); false for NaN. */
bool fs_griffith_extends(double e1, double e2, double a, double gc);

#endif
