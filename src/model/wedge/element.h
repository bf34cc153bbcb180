/* The 6-node wedge (triangular prism) finite element: shape functions, quadrature, stiffness, stresses. */
#ifndef FS_MODEL_WEDGE_ELEMENT_H
#define FS_MODEL_WEDGE_ELEMENT_H

/* Conventions (thesis §5.3).
 *
 * Nodes: 0, 1, 2 are the bottom triangle, counter-clockwise seen from above (from the top face);
 * 3, 4, 5 are the top triangle, node 3 above node 0, 4 above 1, 5 above 2.
 * Coordinates: x[3*i + k] is coordinate k (x, y, z) of node i, the layout of the model's flat
 * position arrays. Displacements u and nodal forces f use the same layout (18 values, thesis
 * Eq. 5.3–5.5).
 * Natural coordinates (r, s, zeta) are the thesis' (xi, eta, zeta), Fig. 5.6: r, s >= 0, r + s <= 1
 * on the triangle, zeta in [-1, 1] from the bottom face to the top face. Node 0 sits at
 * (r, s) = (1, 0), node 1 at (0, 1), node 2 at (0, 0) (thesis Eq. 5.9–5.14, nodes n1..n6 there).
 * Voigt order: xx, yy, zz, xy, yz, zx (see fracture/eigen.h). Strains carry engineering shears
 * (gamma_xy = du/dy + dv/dx); stresses carry tensor shears.
 * Units: lengths in cm, E in MPa, so stresses are in MPa and forces in MPa cm^2 (= 100 N); strains
 * are dimensionless.
 * Row-major matrices: D is 6x6 (D[6*i + j]), K is 18x18 (K[18*i + j]). */

#define FS_WEDGE_NODES 6
#define FS_WEDGE_DOF 18
#define FS_WEDGE_GAUSS 9
/* The Gauss points 0..2 are the three nearest the top face, where thesis §5.6.1 evaluates the
 * stress that decides fracture; 3..5 are at mid-thickness, 6..8 nearest the bottom. */
#define FS_WEDGE_GAUSS_TOP 3

/* Gauss points and weights: {r, s, zeta, weight}, thesis Table 5.1 in its order (see wedge_element.c
 * for the weight normalisation). The weights sum to 1, the volume of the reference wedge. */
extern const double fs_wedge_gauss[FS_WEDGE_GAUSS][4];

/* Shape function values N_i(r, s, zeta), i = 0..5. They sum to 1. */
void fs_wedge_shape(double r, double s, double zeta, double n[6]);

/* Natural derivatives: dn[3*i + k] = dN_i / d(r, s, zeta)_k. */
void fs_wedge_shape_deriv(double r, double s, double zeta, double dn[18]);

/* Cartesian derivatives of the shape functions at (r, s, zeta): dndx[3*i + k] = dN_i / dx_k, and the
 * Jacobian determinant (the volume scale d(x,y,z) / d(r,s,zeta)) in *detj.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) if det J <= 0 (inverted or degenerate element; dndx is
 * then unset, *detj still holds the determinant). */
int fs_wedge_gradients(const double x[18], double r, double s, double zeta, double dndx[18], double *detj);

/* The isotropic material stiffness matrix D(E, nu) (thesis Eq. 5.32): stress = D strain.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) unless E > 0 and -1 < nu < 0.5. */
int fs_wedge_elasticity(double young, double poisson, double D[36]);

/* Element volume: sum over the Gauss points of det J w (cm^3), exact for the isoparametric wedge.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) for an inverted or degenerate element. */
int fs_wedge_volume(const double x[18], double *volume);

/* The element stiffness K = sum_g B^T D B det J w (thesis Eq. 5.42), 18x18, symmetric exactly
 * (the upper triangle is computed and mirrored). Nodal forces of the element are K u (MPa cm^2).
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) for an inverted or degenerate element (K unset). */
int fs_wedge_stiffness(const double x[18], const double D[36], double K[324]);

/* Strain B u (Voigt, engineering shears) at natural point (r, s, zeta). Returns 0 or -1 as above. */
int fs_wedge_strain(const double x[18], const double u[18], double r, double s, double zeta,
                    double strain[6]);

/* Stress D (B u - eps0) at every Gauss point (stress_gauss[6*g + c], in fs_wedge_gauss order) and at
 * the element centre (r, s, zeta) = (1/3, 1/3, 0); either output may be NULL. eps0 is the eigenstrain
 * (initial strain, Voigt with engineering shears, constant over the element): the strain the
 * material would take if free, e.g. -shrinkage or +growth; NULL means zero.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) for an inverted or degenerate element. */
int fs_wedge_stress(const double x[18], const double D[36], const double u[18], const double eps0[6],
                    double stress_gauss[54], double stress_centre[6]);

/* The equivalent nodal force of an eigenstrain: f = sum_g B^T D eps0 det J w (MPa cm^2). It is
 * self-equilibrated (zero net force and moment), and equilibrium of the element with nodal
 * displacements u and external forces f_ext reads K u = f + f_ext; a free element therefore takes
 * the displacement whose strain is eps0 and is stress-free.
 * Returns 0, or -1 with fs_error(FS_ERR_DATA) for an inverted or degenerate element (f unset). */
int fs_wedge_eigenstrain_force(const double x[18], const double D[36], const double eps0[6], double f[18]);

#endif
