/* The separation tensor of O'Brien & Hodgins (1999, §4.1-4.2): tensile and compressive parts of a stress, and the tensor a node's element forces make. */
#ifndef FS_FRACTURE_SEPARATION_H
#define FS_FRACTURE_SEPARATION_H

/* Conventions: stresses are Voigt vectors with tensor shears (fracture/eigen.h: xx, yy, zz, xy, yz,
 * zx); forces are 3-vectors in the caller's units; the separation tensor is a symmetric tensor in
 * the same Voigt layout, in force units. */

/* design: O'Brien & Hodgins Eq. 28-30. With v_i, n_i the eigenvalues and unit eigenvectors of the
 * stress (fs_eigen_sym3), the tensile part is sum_i max(0, v_i) n_i n_i^T and the compressive part
 * sum_i min(0, v_i) n_i n_i^T (their m(n_i) is n_i n_i^T for a unit vector); plus + minus = stress up
 * to rounding. A stress with no positive eigenvalue has plus = 0 exactly and minus = stress; one with
 * no negative eigenvalue the reverse (fs_eigen_principal_bound decides most cases without the
 * decomposition). Returns 0, or -1 with fs_error(FS_ERR_INTERNAL) for a non-finite stress (outputs
 * zero). */
int fs_separation_split(const double stress[6], double plus[6], double minus[6]);

/* The sum over the elements at one node (O'Brien & Hodgins §4.2). */
typedef struct {
    double f_plus[3];   /* the unbalanced tensile load: sum of the tensile forces */
    double f_minus[3];  /* the unbalanced compressive load */
    double m_plus[6];   /* sum of m(f) over the tensile forces */
    double m_minus[6];  /* sum of m(f) over the compressive forces */
} fs_separation;

/* m(a) = a a^T / |a| (0 for a = 0), O'Brien & Hodgins Eq. 28: |a| is its eigenvalue along a. */
void fs_separation_m(const double a[3], double m[6]);

void fs_separation_init(fs_separation *s);

/* Adds the tensile force f_plus and the compressive force f_minus one element exerts on the node
 * (the nodal forces of its stress's two parts, computed as the element computes its nodal forces). */
void fs_separation_add(fs_separation *s, const double f_plus[3], const double f_minus[3]);

/* design: O'Brien & Hodgins Eq. 32:
 *     zeta = 1/2 ( -m(f+) + sum m(f) over {f+} + m(f-) - sum m(f) over {f-} ).
 * Balanced tensile forces pulling the node apart from both sides add to its largest eigenvalue; the
 * unbalanced part (what would translate the node, e.g. at a loaded boundary) is removed, and
 * compression across a plane lowers it. It is invariant under rotations of the frame. */
void fs_separation_tensor(const fs_separation *s, double zeta[6]);

/* The eigenvalues of zeta (descending) and their unit eigenvectors (vectors + 3 k), as
 * fs_eigen_sym3: fracture planes in order of preference. Returns 0 or -1 as fs_eigen_sym3. */
int fs_separation_eigen(const double zeta[6], double values[3], double vectors[9]);

/* The largest eigenvalue of zeta and its unit eigenvector (the normal of the fracture plane,
 * O'Brien & Hodgins §4.2), deterministic as fs_eigen_sym3's. Returns 0 or -1 as fs_eigen_sym3. */
int fs_separation_largest(const double zeta[6], double *value, double normal[3]);

#endif
