/* Dense linear algebra for the element tests: eigenvalues of small symmetric matrices. */
#ifndef FS_TESTS_DENSE_H
#define FS_TESTS_DENSE_H

#include <math.h>

/* Eigenvalues of a symmetric n x n matrix (row-major) by cyclic Jacobi, in ascending order into
 * values; a is destroyed. */
static void jacobi_eigenvalues(double *a, int n, double *values)
{
    for (int sweep = 0; sweep < 100; sweep++) {
        double off = 0.0, all = 0.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                all += a[n * i + j] * a[n * i + j];
                if (i != j)
                    off += a[n * i + j] * a[n * i + j];
            }
        if (off <= 1e-32 * all)
            break;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) {
                double apq = a[n * p + q];
                if (apq == 0.0)
                    continue;
                double theta = 0.5 * (a[n * q + q] - a[n * p + p]) / apq;
                double t = 1.0 / (fabs(theta) + sqrt(1.0 + theta * theta));
                if (theta < 0.0)
                    t = -t;
                double c = 1.0 / sqrt(1.0 + t * t), s = t * c;
                for (int k = 0; k < n; k++) { /* columns p, q */
                    double akp = a[n * k + p], akq = a[n * k + q];
                    a[n * k + p] = c * akp - s * akq;
                    a[n * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < n; k++) { /* rows p, q */
                    double apk = a[n * p + k], aqk = a[n * q + k];
                    a[n * p + k] = c * apk - s * aqk;
                    a[n * q + k] = s * apk + c * aqk;
                }
            }
    }
    for (int i = 0; i < n; i++)
        values[i] = a[n * i + i];
    for (int i = 1; i < n; i++) /* ascending */
        for (int j = i; j > 0 && values[j] < values[j - 1]; j--) {
            double t = values[j];
            values[j] = values[j - 1];
            values[j - 1] = t;
        }
}

#endif
