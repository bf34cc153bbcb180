/* The linear tetrahedron (O'Brien & Hodgins §3.2): shape-function gradients, stiffness, strain, stress and nodal forces. */
#ifndef FS_MODEL_TET_ELEMENT_H
#define FS_MODEL_TET_ELEMENT_H

/* Conventions: corner c of an element has coordinates x[3*c + k] (cm); displacements u and nodal
 * forces f use the same layout (12 values). Voigt order xx, yy, zz, xy, yz, zx (fracture/eigen.h):
 * strains with engineering shears, stresses with tensor shears. E in MPa, so stresses are in MPa
 * and forces in MPa cm^2. Row-major 12 x 12 stiffness.
 *
 * design: the shape functions are the barycentric coordinates, N = beta [x; 1] (O'Brien & Hodgins
 * Eq. 15-16), so their gradients g_c = dN_c/dx are the first three columns of beta's rows and are
 * constant over the element; they sum to zero. The strain measure is the small (linearized) strain
 * eps = sym(sum_c u_c g_c^T), the first-order part of the paper's Green strain (Eq. 1): the layer's
 * equilibrium is then linear, so one factorization serves every time and load of an unchanged mesh,
 * the state at any time is a sum of a few load cases, and the event search in time needs no solve.
 * That is sound here: a layer bonded to its substrate turns by small angles (a curled edge by a tenth
 * of a radian puts a spurious strain of 0.005 where the Green strain puts none, against shrinkage
 * strains of a few per cent), while the paper's objects tumble freely. An infinitesimal rotation
 * u = w x r has zero small strain and exerts no force (a test checks this and the six zero modes).
 * The nodal forces an element exerts on its corners are f_c = -vol sigma g_c (the paper's Eq. 24
 * with its first-order strain), and the stiffness is K = vol B^T D B:
 *     K_ab = vol (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I). */

/* Lame's constants from Young's modulus and Poisson's ratio: lambda = E nu / ((1 + nu)(1 - 2 nu)),
 * mu = E / (2 (1 + nu)). Returns 0, or -1 unless E > 0 and -1 < nu < 0.5. */
int fs_tet_lame(double young, double poisson, double *lambda, double *mu);

/* The gradients g[3*c + k] = dN_c/dx_k and the signed volume. Returns 0, or -1 when the volume is not
 * positive (g then unset). */
int fs_tet_gradients(const double x[12], double g[12], double *volume);

/* The 12 x 12 stiffness from the gradients and volume. */
void fs_tet_stiffness(const double g[12], double volume, double lambda, double mu, double K[144]);

/* The strain of displacements u (Voigt, engineering shears). */
void fs_tet_strain(const double g[12], const double u[12], double strain[6]);

/* The stress lambda tr(e) I + 2 mu e of strain e (Voigt, engineering shears in, tensor shears out). */
void fs_tet_stress(double lambda, double mu, const double strain[6], double stress[6]);

/* The forces f[3*c + k] = -vol (sigma g_c)_k the element exerts on its corners under stress sigma. */
void fs_tet_forces(const double g[12], double volume, const double stress[6], double f[12]);

#endif
