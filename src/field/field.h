/* Material, growth and shrinkage parameters (thesis ch. 3, §5.9): the fields the physical models read. */
#ifndef FS_FIELD_FIELD_H
#define FS_FIELD_FIELD_H

#include <stdbool.h>

#define FS_PWL_MAX 32

/* Piecewise-linear function of time given as "t:value" pairs with increasing t; constant outside. */
typedef struct {
    int n;                   /* number of knots, 0 means the constant 0 */
    double t[FS_PWL_MAX];
    double v[FS_PWL_MAX];
} fs_pwl;

double fs_pwl_eval(const fs_pwl *f, double t);

typedef struct {
    double young;           /* Young's modulus E (MPa) */
    double poisson;         /* Poisson's ratio nu */
    double threshold;       /* threshold stress (kPa) */
    double toughness;       /* fracture toughness (J/m^2) */
    double thickness;       /* layer thickness at t = 0 (cm) */
    double thickness_final; /* thickness at time.end (cm); linear in between; < 0 means constant */
    double jitter;          /* relative random per-element perturbation of the threshold, [0, 1) */
} fs_material;

typedef enum { FS_GROWTH_NONE = 0, FS_GROWTH_PLANAR, FS_GROWTH_CYLINDER, FS_GROWTH_SPHERE } fs_growth_type;

typedef struct {
    fs_growth_type type;
    double r1, r2;      /* planar growth tensor: relative growth rates along its two axes (1/time unit) */
    double angle;       /* planar: direction of the r1 axis (degrees from x) */
    double rate;        /* cylinder / sphere: rate of growth of the radius (cm per time unit) */
    double axis_ratio;  /* sphere: growth along the z axis relative to around it (1 = isogonic) */
} fs_growth;

typedef struct {
    fs_pwl top;     /* shrinkage of the top of the layer over time (relative length change, > 0 shrinks) */
    fs_pwl bottom;  /* shrinkage of the bottom of the layer */
} fs_shrink;

fs_material fs_material_default(void);
fs_growth fs_growth_default(void);
fs_shrink fs_shrink_default(void);

const char *fs_growth_type_name(fs_growth_type t);

#endif
