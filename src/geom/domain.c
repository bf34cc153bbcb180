/* Simulation domains: extents, periodic wrapping, 3-D embedding and texture-space maps. */
#include "geom/domain.h"

#include <math.h>

#include "base/vec.h"

fs_domain fs_domain_default(void)
{
    fs_domain d = {
        .type = FS_DOMAIN_PLANE,
        .width = 10.0,
        .height = 10.0,
        .radius = 5.0,
        .periodic_x = false,
        .periodic_y = false,
    };
    return d;
}

void fs_domain_normalize(fs_domain *d)
{
    if (d->type == FS_DOMAIN_CYLINDER)
        d->periodic_x = true;
    else if (d->type == FS_DOMAIN_SPHERE || d->type == FS_DOMAIN_MESH)
        d->periodic_x = d->periodic_y = false;
}

double fs_domain_extent_x(const fs_domain *d)
{
    return d->type == FS_DOMAIN_PLANE || d->type == FS_DOMAIN_MESH ? d->width : 2.0 * FS_PI * d->radius;
}

double fs_domain_extent_y(const fs_domain *d)
{
    return d->type == FS_DOMAIN_SPHERE ? FS_PI * d->radius : d->height;
}

double fs_domain_area(const fs_domain *d)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH:
        return d->width * d->height;
    case FS_DOMAIN_CYLINDER:
        return 2.0 * FS_PI * d->radius * d->height;
    case FS_DOMAIN_SPHERE:
        return 4.0 * FS_PI * d->radius * d->radius;
    }
    return 0.0;
}

static bool periodic_x(const fs_domain *d) { return d->type == FS_DOMAIN_CYLINDER || d->periodic_x; }

/* x modulo period into [0, period); the second test catches -tiny rounding up to period. */
static double wrap_coord(double x, double period)
{
    double w = x - floor(x / period) * period;
    return (w >= period || w < 0.0) ? 0.0 : w;
}

void fs_domain_wrap(const fs_domain *d, double *p)
{
    if (d->type == FS_DOMAIN_SPHERE) {
        double r = fs_norm3(p);
        if (r > 0.0) {
            double k = d->radius / r;
            p[0] *= k;
            p[1] *= k;
            p[2] *= k;
        } else {
            p[0] = p[1] = 0.0;
            p[2] = d->radius;
        }
        return;
    }
    if (periodic_x(d))
        p[0] = wrap_coord(p[0], fs_domain_extent_x(d));
    if (d->periodic_y)
        p[1] = wrap_coord(p[1], fs_domain_extent_y(d));
}

void fs_domain_delta(const fs_domain *d, const double *a, const double *b, double *out)
{
    fs_sub3(out, b, a);
    if (d->type == FS_DOMAIN_SPHERE)
        return;
    if (periodic_x(d)) {
        double px = fs_domain_extent_x(d);
        out[0] -= px * round(out[0] / px);
    }
    if (d->periodic_y) {
        double py = fs_domain_extent_y(d);
        out[1] -= py * round(out[1] / py);
    }
}

void fs_domain_embed(const fs_domain *d, const double *p, double *world)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH:
        world[0] = p[0];
        world[1] = p[1];
        world[2] = 0.0;
        return;
    case FS_DOMAIN_CYLINDER: {
        double a = p[0] / d->radius;
        world[0] = d->radius * cos(a);
        world[1] = d->radius * sin(a);
        world[2] = p[1];
        return;
    }
    case FS_DOMAIN_SPHERE:
        world[0] = p[0];
        world[1] = p[1];
        world[2] = p[2];
        return;
    }
}

void fs_domain_normal(const fs_domain *d, const double *p, double *n)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_MESH:
        n[0] = 0.0;
        n[1] = 0.0;
        n[2] = 1.0;
        return;
    case FS_DOMAIN_CYLINDER: {
        double a = p[0] / d->radius;
        n[0] = cos(a);
        n[1] = sin(a);
        n[2] = 0.0;
        return;
    }
    case FS_DOMAIN_SPHERE: {
        double r = fs_norm3(p);
        if (r > 0.0) {
            n[0] = p[0] / r;
            n[1] = p[1] / r;
            n[2] = p[2] / r;
        } else {
            n[0] = n[1] = 0.0;
            n[2] = 1.0;
        }
        return;
    }
    }
}

void fs_domain_to_uv(const fs_domain *d, const double *p, double *uv)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_CYLINDER:
    case FS_DOMAIN_MESH:
        uv[0] = p[0] / fs_domain_extent_x(d);
        uv[1] = p[1] / fs_domain_extent_y(d);
        return;
    case FS_DOMAIN_SPHERE: {
        double u = atan2(p[1], p[0]) / (2.0 * FS_PI);
        if (u < 0.0)
            u += 1.0;
        if (u >= 1.0)
            u = 0.0;
        double s = p[2] / d->radius;
        s = s > 1.0 ? 1.0 : (s < -1.0 ? -1.0 : s);
        uv[0] = u;
        uv[1] = (asin(s) + 0.5 * FS_PI) / FS_PI;
        return;
    }
    }
}

void fs_domain_from_uv(const fs_domain *d, const double *uv, double *p)
{
    switch (d->type) {
    case FS_DOMAIN_PLANE:
    case FS_DOMAIN_CYLINDER:
    case FS_DOMAIN_MESH:
        p[0] = uv[0] * fs_domain_extent_x(d);
        p[1] = uv[1] * fs_domain_extent_y(d);
        p[2] = 0.0;
        return;
    case FS_DOMAIN_SPHERE: {
        double lon = 2.0 * FS_PI * uv[0];
        double lat = FS_PI * uv[1] - 0.5 * FS_PI;
        p[0] = d->radius * cos(lat) * cos(lon);
        p[1] = d->radius * cos(lat) * sin(lon);
        p[2] = d->radius * sin(lat);
        return;
    }
    }
}

bool fs_domain_wraps_u(const fs_domain *d)
{
    return d->type == FS_DOMAIN_CYLINDER || d->type == FS_DOMAIN_SPHERE || (d->type == FS_DOMAIN_PLANE && d->periodic_x);
}

bool fs_domain_wraps_v(const fs_domain *d)
{
    return (d->type == FS_DOMAIN_PLANE || d->type == FS_DOMAIN_CYLINDER) && d->periodic_y;
}

const char *fs_domain_type_name(fs_domain_type t)
{
    switch (t) {
    case FS_DOMAIN_PLANE:
        return "plane";
    case FS_DOMAIN_CYLINDER:
        return "cylinder";
    case FS_DOMAIN_SPHERE:
        return "sphere";
    case FS_DOMAIN_MESH:
        return "mesh";
    }
    return "unknown";
}
