/* Material, growth and shrinkage parameters: their defaults and the piecewise-linear functions of time. */
#include "field/field.h"

#include <string.h>

double fs_pwl_eval(const fs_pwl *f, double t)
{
    if (f->n <= 0)
        return 0.0;
    if (!(t > f->t[0]))
        return f->v[0];
    if (!(t < f->t[f->n - 1]))
        return f->v[f->n - 1];
    int i = 0;
    while (!(t < f->t[i + 1]))
        i++;
    double s = (t - f->t[i]) / (f->t[i + 1] - f->t[i]);
    return f->v[i] + (f->v[i + 1] - f->v[i]) * s;
}

fs_material fs_material_default(void)
{
    fs_material m;
    memset(&m, 0, sizeof m);
    m.young = 10000.0;
    m.poisson = 0.3;
    m.threshold = 200.0;
    m.toughness = 200.0;
    m.thickness = 0.5;
    m.thickness_final = -1.0;
    m.jitter = 0.1;
    return m;
}

fs_growth fs_growth_default(void)
{
    fs_growth g;
    memset(&g, 0, sizeof g);
    g.type = FS_GROWTH_NONE;
    g.r1 = 1.0;
    g.r2 = 1.0;
    g.angle = 0.0;
    g.rate = 1.0;
    g.axis_ratio = 1.0;
    return g;
}

fs_shrink fs_shrink_default(void)
{
    fs_shrink s;
    memset(&s, 0, sizeof s);
    return s;
}

const char *fs_growth_type_name(fs_growth_type t)
{
    switch (t) {
    case FS_GROWTH_NONE: return "none";
    case FS_GROWTH_PLANAR: return "planar";
    case FS_GROWTH_CYLINDER: return "cylinder";
    case FS_GROWTH_SPHERE: return "sphere";
    }
    return "unknown";
}
