/* Nodal fracture criteria for any model: the principal plane of a node's averaged stress, and the separation tensor of its tensile and compressive forces (O'Brien and Hodgins 1999). */
#ifndef FS_FRACTURE_SEPARATION_H
#define FS_FRACTURE_SEPARATION_H

#include <stdbool.h>
#include <stdint.h>

/* design: two ways to decide whether, and along which plane, the material at a node fails. Both
 * read only stresses or forces, so a triangle, wedge or tetrahedral model calls them alike; stresses
 * are Voigt vectors with tensor shears (fracture/eigen.h), matrices row-major 3x3.
 *
 * The nodal principal plane (thesis §5.7.1): the stresses a node's elements have next to it are
 * averaged, and the largest principal stress of the mean, against the mean threshold, is the node's
 * ratio; the fracture plane is normal to its principal direction. fs_nodal_stress accumulates the
 * mean in the order the elements are given; fs_nodal_principal_plane decomposes it.
 *
 * The separation tensor (O'Brien and Hodgins, "Graphical modeling and animation of brittle
 * fracture", SIGGRAPH 1999, §4.1-4.2): each element's stress is split by the sign of its eigenvalues
 * into a tensile and a compressive part (Eqs. 29-30, fs_separation_split_stress); the forces an
 * element exerts on its nodes are evaluated with each part (the model's own element force, Eq. 31:
 * f+ from sigma+, f- = f - f+), giving every node a set of tensile forces {f+} and a set of
 * compressive forces {f-}. With m(a) = a a^T / |a| (0 for a = 0; Eq. 28) and F+, F- the sums of the
 * sets, the separation tensor of the node is (Eq. 32)
 *     zeta = 1/2 ( -m(F+) + sum m(f+) + m(F-) - sum m(f-) ).
 * Its largest eigenvalue v+, when positive, measures how strongly balanced forces pull the node
 * apart (the material fails where v+ exceeds its toughness), and the fracture plane is normal to
 * the eigenvector of v+ (fs_separation_largest). Unbalanced forces, which would move the node
 * rigidly, do not count: one force alone gives zeta = 0. */

/* The running mean of the stresses around a node. Zero it ({0}) first. */
typedef struct {
    double sum[6];
    int32_t count;
} fs_nodal_stress;

/* Adds an element's stress s (Voigt) to the node's sum. */
void fs_nodal_stress_add(fs_nodal_stress *a, const double s[6]);

/* The mean of the stresses added (sum / count, component by component) into mean; false (mean
 * zeroed) when none were. */
bool fs_nodal_stress_mean(const fs_nodal_stress *a, double mean[6]);

/* design: the direction a crack tip runs in. The stress of the element just ahead of a tip varies
 * from element to element on the scale of the mesh (a coarse mesh resolves the tip's concentration
 * in whichever element it happens to fall), and a crack that follows each element's own principal
 * plane zigzags with the elements. The tip stress instead averages the stress samples in front of
 * the tip (offset o from the tip with o . ahead > 0, ahead the direction the crack travelled) with
 * the weight size * exp(-(|o| / radius)^2), the nonlocal average by which continuum fracture codes
 * steer their cracks: on a symmetric (mode I) field ahead of a tip the shears cancel and the crack
 * runs straight on; a mixed-mode field turns it, on the scale of the radius rather than of one
 * element. Samples behind the tip (the unloaded crack walls, whose stress along the crack would turn
 * it aside) and beyond 3 radii do not count.
 *
 * On a curved layer (a sphere, a trunk, a shell) each sample's stress lies in its own tangent plane:
 * it is turned into the tip's by the smallest rotation that takes the sample's surface normal onto
 * the tip's (parallel transport, exact for a sphere), samples whose normal is 60 degrees or more
 * from the tip's do not count, and the mean is projected onto the tip's tangent plane, so the plane
 * it gives is across the layer. */

/* The running weighted mean of the stresses ahead of a crack tip. Start it with fs_tip_stress_begin. */
typedef struct {
    double sum[6];
    double weight;
    double ahead[3], radius;
    double normal[3];
    bool surface;
} fs_tip_stress;

/* Starts the mean for a tip whose crack travelled along ahead (3-D, any length) with the averaging
 * radius radius (> 0, the model's length unit); normal is the surface's unit normal at the tip, or
 * NULL for a volume (no turning, no projection). */
void fs_tip_stress_begin(fs_tip_stress *a, const double ahead[3], const double normal[3], double radius);

/* Adds the stress s (Voigt) of a sample at offset (3-D, from the tip) standing for size (an area or
 * volume, >= 0) of material; normal is the surface's unit normal at the sample (may be NULL: taken
 * as the tip's). */
void fs_tip_stress_add(fs_tip_stress *a, const double offset[3], const double normal[3], double size,
                       const double s[6]);

/* The weighted mean into mean (on a surface, projected onto the tip's tangent plane); false (mean
 * zeroed) when no sample ahead of the tip had weight. */
bool fs_tip_stress_mean(const fs_tip_stress *a, double mean[6]);

/* The 3-D Voigt stress of the plane stress (plane: sxx, syy, sxy) in the orthonormal frame e1, e2 of
 * a surface: sxx e1 e1^T + syy e2 e2^T + sxy (e1 e2^T + e2 e1^T). */
void fs_plane_stress_voigt(const double e1[3], const double e2[3], const double plane[3], double out[6]);

/* The largest principal stress of a Voigt stress into *sigma1 and, if normal is not NULL, the unit
 * normal of its principal plane (the eigenvector of sigma1, oriented as fs_eigen_sym3 orients it).
 * Returns 0, or -1 with fs_error (FS_ERR_INTERNAL) if an entry is not finite (outputs zeroed). */
int fs_nodal_principal_plane(const double stress[6], double *sigma1, double normal[3]);

/* The tensile part sigma+ = sum max(0, v_i) n_i n_i^T and the compressive part sigma- = sum
 * min(0, v_i) n_i n_i^T of a Voigt stress (O'Brien and Hodgins Eqs. 29-30; v_i, n_i its eigenvalues
 * and unit eigenvectors), so that stress = plus + minus. Either output may be NULL. Returns 0, or -1
 * with fs_error if an entry is not finite (outputs zeroed). */
int fs_separation_split_stress(const double stress[6], double plus[6], double minus[6]);

/* zeta += scale m(a), m(a) = a a^T / |a| (0 for a = 0): Eq. 28, a symmetric 3x3 with eigenvalue |a|
 * along a and 0 across it. Each off-diagonal term is added to both triangles, so a symmetric zeta
 * stays exactly symmetric. */
void fs_separation_add_m(double zeta[9], const double a[3], double scale);

/* The separation tensor (Eq. 32) of a node from the tensile forces f_plus (n_plus of them, 3
 * components each) and the compressive forces f_minus (n_minus) its elements exert on it, into zeta
 * (row-major, symmetric). The sums run in the order given. */
void fs_separation_tensor(const double *f_plus, int32_t n_plus, const double *f_minus, int32_t n_minus,
                          double zeta[9]);

/* The largest eigenvalue v+ of the separation tensor into *value and its unit eigenvector (the
 * normal of the fracture plane) into normal (may be NULL). v+ <= 0 means nothing pulls the node
 * apart. Returns 0, or -1 with fs_error if an entry is not finite. */
int fs_separation_largest(const double zeta[9], double *value, double normal[3]);

#endif
