/* Symmetric 3x3 eigen decomposition, principal stresses and strains, von Mises stress. */
#ifndef FS_FRACTURE_EIGEN_H
#define FS_FRACTURE_EIGEN_H

/* Voigt order used by every kernel and model in fissure: index 0..5 = xx, yy, zz, xy, yz, zx
 * (thesis Eq. 5.52 and Eq. 5.31). A stress vector holds the tensor components (sigma_xx, ...,
 * tau_xy, tau_yz, tau_zx); a strain vector holds engineering shears (gamma_xy = 2 eps_xy, ...), so
 * that stress = D strain with the usual isotropic D. Units are the caller's (fissure: MPa). */

/* Decomposes the symmetric matrix a (row-major 3x3; only the upper triangle a[1], a[2], a[5] is read
 * off the diagonal) as a = V diag(values) V^T.
 * values: the eigenvalues in descending order (values[0] >= values[1] >= values[2]).
 * vectors: if not NULL, vectors + 3*k is the unit eigenvector of values[k]; the three form a
 *   right-handed orthonormal basis (vectors[6..8] = vectors[0..2] x vectors[3..5]), and the largest
 *   component (the first of equal ones) of the first two is positive, so the output is deterministic.
 * Diagonal matrices (including zero and repeated eigenvalues) are returned exactly: values are the
 * sorted diagonal and vectors are signed unit axes. Accuracy: |a - V diag V^T| is a few ulps of |a|.
 * Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) if an entry is not finite (outputs then zero). */
int fs_eigen_sym3(const double a[9], double values[3], double vectors[9]);

/* Principal stresses (descending) of a stress given as 6 Voigt components (tensor shears), and, if
 * dirs is not NULL, the normals of the principal planes as in fs_eigen_sym3. Returns 0 or -1. */
int fs_eigen_principal_stress(const double stress[6], double sigma[3], double dirs[9]);

/* Principal strains (descending) of a strain given as 6 Voigt components with engineering shears
 * (halved here to form the tensor). dirs as above. Returns 0 or -1. */
int fs_eigen_principal_strain(const double strain[6], double eps[3], double dirs[9]);

/* An upper bound of the largest principal stress (fs_eigen_principal_stress's sigma[0]) of a Voigt
 * stress, tight (within a relative 1e-6 of the deviator's size) where it exceeds level; where it is
 * at most level it may be loose. Never below the kernel's value, rounding included. Non-finite input
 * gives a non-finite result. */
double fs_eigen_principal_bound(const double s[6], double level);

/* Von Mises equivalent stress of a Voigt stress (tensor shears):
 * sqrt(((sxx-syy)^2 + (syy-szz)^2 + (szz-sxx)^2) / 2 + 3 (txy^2 + tyz^2 + tzx^2)). */
double fs_eigen_von_mises(const double stress[6]);

#endif
