/* Tests of presets: defaults, INI parsing and its error messages, --set, dump round trips, the preset path. */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/error.h"
#include "check.h"
#include "field/field.h"
#include "io/preset.h"
#include "sim/settings.h"

/* Every key set away from its default. */
static const char *const full_preset =
    "# a preset touching every key\n"
    "[preset]\n"
    "name = full-test_1.0\n"
    "description = Every key, for the round trip; with: colons = and #hashes\n"
    "model = wedge\n"
    "seed = 18446744073709551615\n"
    "[domain]\n"
    "type = cylinder\n"
    "width = 12.5\n"
    "height = 40\n"
    "radius = 5\n"
    "periodic = y\n"
    "[mesh]\n"
    "elements = 5000\n"
    "min_size = 0.01\n"
    "lattice = hex\n"
    "relax_iterations = 0\n"
    "radius_jitter = 0.9\n"
    "refine_vm = 0.35\n"
    "refine_vm_rounds = 7\n"
    "smooth_radius = 2.5\n"
    "smooth_iterations = 5\n"
    "[material]\n"
    "young = 12000.5\n"
    "poisson = 0.499\n"
    "threshold = 1400\n"
    "toughness = 0\n"
    "thickness = 0.03\n"
    "thickness_final = 0.3\n"
    "thickness_map = textures/ramp.png\n"
    "young_map = /abs/young.png\n"
    "threshold_map = t.png\n"
    "jitter = 0.99\n"
    "[growth]\n"
    "type = cylinder\n"
    "r1 = -0.5\n"
    "r2 = 2\n"
    "angle = 0.30000000000000004\n"
    "rate = 1e-300\n"
    "axis_ratio = 4\n"
    "[shrink]\n"
    "top = 0:0, 0.5:0.1, 1:0.1\n"
    "bottom = 0:-0.5\n"
    "[fracture]\n"
    "method = remove\n"
    "griffith = off\n"
    "tip_submodel = on\n"
    "tip_submodel_radius = 6\n"
    "tip_submodel_size = 0.125\n"
    "[time]\n"
    "end = 2.5\n"
    "min_step = 0.001\n"
    "[render]\n"
    "size = 640x480\n"
    "height_scale = 2.5\n"
    "supersample = 8\n"
    "normal = directx\n"
    "color_material = #D0AE8C\n"
    "color_crack = #543a2a\n"
    "color_background = #000000\n"
    "color_variation = 1\n"
    "[voronoi]\n"
    "crack_width = 0\n"
    "bevel = 0.3\n"
    "depth = 0.7\n"
    "warp = 0\n"
    "warp_scale = 1.5\n"
    "subdivisions = 64\n";

static bool pwl_equal(const fs_pwl *a, const fs_pwl *b)
{
    if (a->n != b->n)
        return false;
    for (int i = 0; i < a->n; i++)
        if (a->t[i] != b->t[i] || a->v[i] != b->v[i])
            return false;
    return true;
}

static bool color_equal(const float *a, const float *b, double tol)
{
    for (int i = 0; i < 3; i++)
        if (!(fabs((double)a[i] - (double)b[i]) <= tol))
            return false;
    return true;
}

/* The name of the first field that differs (colours within tol), or NULL when the configs are equal. */
static const char *config_diff(const fs_config *a, const fs_config *b, double color_tol)
{
#define SAME(f)                  \
    do {                         \
        if (!(a->f == b->f))     \
            return #f;           \
    } while (0)
#define SAME_STR(f)                \
    do {                           \
        if (strcmp(a->f, b->f))    \
            return #f;             \
    } while (0)
    SAME_STR(preset.name);
    SAME_STR(preset.description);
    SAME(preset.model);
    SAME(preset.seed);
    SAME(domain.type);
    SAME(domain.width);
    SAME(domain.height);
    SAME(domain.radius);
    SAME(domain.periodic_x);
    SAME(domain.periodic_y);
    SAME(mesh.elements);
    SAME(mesh.min_size);
    SAME(mesh.lattice);
    SAME(mesh.relax_iterations);
    SAME(mesh.radius_jitter);
    SAME(mesh.refine_vm);
    SAME(mesh.refine_vm_rounds);
    SAME(mesh.smooth_radius);
    SAME(mesh.smooth_iterations);
    SAME(material.young);
    SAME(material.poisson);
    SAME(material.threshold);
    SAME(material.toughness);
    SAME(material.thickness);
    SAME(material.thickness_final);
    SAME_STR(material_files.thickness_map);
    SAME_STR(material_files.young_map);
    SAME_STR(material_files.threshold_map);
    SAME(material.jitter);
    SAME(growth.type);
    SAME(growth.r1);
    SAME(growth.r2);
    SAME(growth.angle);
    SAME(growth.rate);
    SAME(growth.axis_ratio);
    if (!pwl_equal(&a->shrink.top, &b->shrink.top))
        return "shrink.top";
    if (!pwl_equal(&a->shrink.bottom, &b->shrink.bottom))
        return "shrink.bottom";
    SAME(fracture.method);
    SAME(fracture.griffith);
    SAME(fracture.tip_submodel);
    SAME(fracture.tip_submodel_radius);
    SAME(fracture.tip_submodel_size);
    SAME(time.end);
    SAME(time.min_step);
    SAME(render.width);
    SAME(render.height);
    SAME(render.supersample);
    SAME(render.height_scale);
    SAME(render.normal);
    if (!color_equal(a->render.color_material, b->render.color_material, color_tol))
        return "render.color_material";
    if (!color_equal(a->render.color_crack, b->render.color_crack, color_tol))
        return "render.color_crack";
    if (!color_equal(a->render.color_background, b->render.color_background, color_tol))
        return "render.color_background";
    SAME(render.color_variation);
    SAME(voronoi.crack_width);
    SAME(voronoi.bevel);
    SAME(voronoi.depth);
    SAME(voronoi.warp);
    SAME(voronoi.warp_scale);
    SAME(voronoi.subdivisions);
#undef SAME
#undef SAME_STR
    return NULL;
}

/* The dump of cfg as a malloc'd string. */
static char *dump_string(const fs_config *cfg)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    fs_preset_dump(cfg, f);
    fclose(f);
    return text;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
        exit(1);
    }
    fputs(text, f);
    fclose(f);
}

static void test_defaults(void)
{
    fs_config c = fs_config_default();
    CHECK(!strcmp(c.preset.name, "unnamed"));
    CHECK(c.preset.description[0] == '\0');
    CHECK(c.preset.model == FS_MODEL_VORONOI);
    CHECK(c.preset.seed == 1);
    CHECK(c.mesh.elements == 1000);
    CHECK(c.mesh.min_size == 0.05);
    CHECK(c.mesh.lattice == FS_LATTICE_RANDOM);
    CHECK(c.mesh.relax_iterations == 30);
    CHECK(c.mesh.radius_jitter == 0.2);
    CHECK(c.material.young == 10000 && c.material.poisson == 0.3);
    CHECK(c.material.threshold == 200 && c.material.toughness == 200);
    CHECK(c.material.thickness == 0.5 && c.material.thickness_final == -1);
    CHECK(c.material_files.thickness_map[0] == '\0' && c.material_files.young_map[0] == '\0' &&
          c.material_files.threshold_map[0] == '\0');
    CHECK(c.material.jitter == 0.1);
    CHECK(c.growth.type == FS_GROWTH_NONE && c.growth.r1 == 1 && c.growth.r2 == 1);
    CHECK(c.growth.angle == 0 && c.growth.rate == 1 && c.growth.axis_ratio == 1);
    CHECK(c.shrink.top.n == 0 && c.shrink.bottom.n == 0);
    CHECK(c.fracture.method == FS_FRACTURE_SPLIT && c.fracture.griffith);
    CHECK(!c.fracture.tip_submodel && c.fracture.tip_submodel_radius == 4.0 && c.fracture.tip_submodel_size == 0.25);
    CHECK(c.mesh.refine_vm == 0.0 && c.mesh.refine_vm_rounds == 3 && c.mesh.smooth_radius == 0.0 &&
          c.mesh.smooth_iterations == 3);
    CHECK(c.time.end == 1.0 && c.time.min_step == 1e-4);
    CHECK(!strcmp(fs_model_name(FS_MODEL_SHELL), "shell"));
    CHECK(!strcmp(fs_growth_type_name(FS_GROWTH_CYLINDER), "cylinder"));

    /* The defaults are consistent, and an empty preset leaves them as they are. */
    CHECK(fs_preset_validate(&c, "defaults") == 0);
    fs_config d = fs_config_default();
    CHECK(fs_preset_load_string("", "empty", &d) == 0);
    CHECK(config_diff(&c, &d, 0) == NULL);
    CHECK(fs_preset_load_string("# only a comment\n\n; another\n[mesh]\n", "comments", &d) == 0);
    CHECK(config_diff(&c, &d, 0) == NULL);
}

static void test_full_preset(void)
{
    fs_config c = fs_config_default();
    int rc = fs_preset_load_string(full_preset, "full", &c);
    CHECK_MSG(rc == 0, "%s", fs_error_message());
    CHECK(!strcmp(c.preset.name, "full-test_1.0"));
    CHECK(!strcmp(c.preset.description, "Every key, for the round trip; with: colons = and #hashes"));
    CHECK(c.preset.model == FS_MODEL_WEDGE);
    CHECK(c.preset.seed == UINT64_MAX);
    CHECK(c.domain.type == FS_DOMAIN_CYLINDER && !c.domain.periodic_x && c.domain.periodic_y);
    CHECK(c.mesh.lattice == FS_LATTICE_HEX && c.mesh.relax_iterations == 0);
    CHECK(c.material.thickness_final == 0.3);
    /* A preset from memory has no directory: relative paths stay as written. */
    CHECK(!strcmp(c.material_files.thickness_map, "textures/ramp.png"));
    CHECK(!strcmp(c.material_files.young_map, "/abs/young.png"));
    CHECK(c.growth.type == FS_GROWTH_CYLINDER && c.growth.r1 == -0.5);
    CHECK(c.growth.angle == 0.1 + 0.2 && c.growth.rate == 1e-300);
    CHECK(c.shrink.top.n == 3 && c.shrink.top.t[1] == 0.5 && c.shrink.top.v[2] == 0.1);
    CHECK(c.shrink.bottom.n == 1 && c.shrink.bottom.v[0] == -0.5);
    CHECK(c.fracture.method == FS_FRACTURE_REMOVE && !c.fracture.griffith);
    CHECK(c.fracture.tip_submodel && c.fracture.tip_submodel_radius == 6.0 && c.fracture.tip_submodel_size == 0.125);
    CHECK(c.mesh.refine_vm == 0.35 && c.mesh.refine_vm_rounds == 7 && c.mesh.smooth_radius == 2.5 &&
          c.mesh.smooth_iterations == 5);
    CHECK(c.render.width == 640 && c.render.height == 480 && c.render.supersample == 8);
    CHECK(c.render.normal == FS_NORMAL_DIRECTX);
    /* Colours are decoded from sRGB: black stays 0, 0xD0 = 208 is 0.6308 in linear light. */
    CHECK(c.render.color_background[0] == 0.0f);
    CHECK_NEAR(c.render.color_material[0], 0.630757, 1e-6);
    CHECK_NEAR(c.render.color_material[2], 0.262251, 1e-6);
    CHECK(c.voronoi.subdivisions == 64 && c.voronoi.crack_width == 0);

    /* dump -> parse gives the identical configuration, and dumping that again gives the same text. */
    char *text = dump_string(&c);
    CHECK(!strncmp(text, "# fissure preset (resolved)\n", 28));
    CHECK(strstr(text, "\n[render]\n") && strstr(text, "\ncolor_material = #d0ae8c\n"));
    CHECK(strstr(text, "\nsize = 640x480\n") && strstr(text, "\ngriffith = false\n"));
    CHECK(strstr(text, "\nangle = 0.30000000000000004\n") && strstr(text, "\nr2 = 2\n"));
    CHECK(strstr(text, "\ntop = 0:0, 0.5:0.1, 1:0.1\n") && strstr(text, "\nthickness = 0.03\n"));
    fs_config d = fs_config_default();
    rc = fs_preset_load_string(text, "dump", &d);
    CHECK_MSG(rc == 0, "%s", fs_error_message());
    const char *diff = config_diff(&c, &d, 0);
    CHECK_MSG(diff == NULL, "field %s differs after the round trip", diff);
    char *again = dump_string(&d);
    CHECK(!strcmp(text, again));
    free(text);
    free(again);
}

static void test_default_round_trip(void)
{
    fs_config c = fs_config_default();
    char *text = dump_string(&c);
    CHECK(strstr(text, "\nthickness_final = none\n") && strstr(text, "\ntop = none\n"));
    CHECK(strstr(text, "\nthickness_map =\n") != NULL);
    fs_config d = fs_config_default();
    d.mesh.elements = 77;
    int rc = fs_preset_load_string(text, "dump", &d);
    CHECK_MSG(rc == 0, "%s", fs_error_message());
    /* Colours snap to the nearest 8-bit sRGB value: within half a step of the default. */
    const char *diff = config_diff(&c, &d, 2.5e-3);
    CHECK_MSG(diff == NULL, "field %s differs after the round trip", diff);
    free(text);
}

typedef struct {
    const char *text;
    const char *message;
} error_case;

static void test_errors(void)
{
    static const error_case cases[] = {
        {"[preset]\nname = a\n[colour]\nx = 1\n",
         "t.ini:3: unknown section [colour]: expected one of: preset, domain, mesh, material, growth, shrink, "
         "fracture, time, render, voronoi, solver, wedge, springs, tet, shell"},
        {"[mesh]\n\nelement = 100\n",
         "t.ini:3: unknown key [mesh] element: expected one of: elements, min_size, lattice, relax_iterations, "
         "radius_jitter, refine_vm, refine_vm_rounds, smooth_radius, smooth_iterations"},
        {"[material]\nyoung = 10e\n", "t.ini:2: [material] young: expected a number > 0 (MPa), got '10e'"},
        {"[material]\nyoung = \n", "t.ini:2: [material] young: expected a number > 0 (MPa), got ''"},
        {"[material]\npoisson = 0.5\n", "t.ini:2: [material] poisson: expected a number in [0, 0.499], got '0.5'"},
        {"[material]\nthreshold = nan\n", "t.ini:2: [material] threshold: expected a number > 0 (kPa), got 'nan'"},
        {"[material]\nthickness_final = 0\n",
         "t.ini:2: [material] thickness_final: expected none or a number > 0 (cm), got '0'"},
        {"[domain]\nwidth = 2e6\n", "t.ini:2: [domain] width: expected a number in (0, 1e+06] (cm), got '2e6'"},
        {"[domain]\ntype = torus\n", "t.ini:2: [domain] type: expected plane, cylinder, sphere or mesh, got 'torus'"},
        {"[domain]\nperiodic = z\n", "t.ini:2: [domain] periodic: expected none, x, y or xy, got 'z'"},
        {"[mesh]\nelements = 1000.5\n", "t.ini:2: [mesh] elements: expected an integer in 16..20000000, got '1000.5'"},
        {"[mesh]\nelements = 8\n", "t.ini:2: [mesh] elements: expected an integer in 16..20000000, got '8'"},
        {"[preset]\nseed = -1\n", "t.ini:2: [preset] seed: expected an integer in 0..18446744073709551615, got '-1'"},
        {"[preset]\nname = my preset\n",
         "t.ini:2: [preset] name: expected a name of 1 to 63 characters from A-Z a-z 0-9 . _ -, got 'my preset'"},
        {"[render]\nsize = 1024x8\n",
         "t.ini:2: [render] size: expected WIDTHxHEIGHT in pixels, each in 16..16384, got '1024x8'"},
        {"[render]\nsize = 1024 x 1024\n",
         "t.ini:2: [render] size: expected WIDTHxHEIGHT in pixels, each in 16..16384, got '1024 x 1024'"},
        {"[render]\ncolor_crack = #12345g\n", "t.ini:2: [render] color_crack: expected an sRGB colour #rrggbb, got '#12345g'"},
        {"[fracture]\ngriffith = maybe\n", "t.ini:2: [fracture] griffith: expected true or false, got 'maybe'"},
        {"[mesh]\nrefine_vm = -0.1\n", "t.ini:2: [mesh] refine_vm: expected a number in [0, 100], got '-0.1'"},
        {"[mesh]\nsmooth_iterations = 0\n", "t.ini:2: [mesh] smooth_iterations: expected an integer in 1..100, got '0'"},
        {"[fracture]\ntip_submodel_size = 0\n",
         "t.ini:2: [fracture] tip_submodel_size: expected a number in [0.01, 1] (edge lengths), got '0'"},
        {"[time]\nend = 2\n\n[time]\nend = 3\n",
         "t.ini:5: [time] end: expected one value (already set on line 2), got '3'"},
        {"# comment\nseed = 3\n[preset]\n",
         "t.ini:2: key 'seed' outside any section: expected a '[section]' line before it"},
        {"[mesh]\nelements 500\n", "t.ini:2: syntax error: expected 'key = value' or '[section]'"},
        {"[mesh\nelements = 500\n", "t.ini:1: syntax error: expected 'key = value' or '[section]'"},
        {"[mesh]\n= 500\n", "t.ini:2: syntax error: expected 'key = value' or '[section]'"},
        {"[shrink]\ntop = 0:0, 1:0.1, 0.5:0.2\n",
         "t.ini:2: [shrink] top: expected none or 1 to 32 pairs 't:value' separated by commas, t increasing, "
         "got '0:0, 1:0.1, 0.5:0.2'"},
        {"[shrink]\nbottom = 0:0,\n",
         "t.ini:2: [shrink] bottom: expected none or 1 to 32 pairs 't:value' separated by commas, t increasing, "
         "got '0:0,'"},
        {"[time]\nend = 1\nmin_step = 2\n", "t.ini:3: [time] min_step: expected less than [time] end (1), got '2'"},
        {"[time]\nend = 0.00005\n", "t.ini:2: [time] end: expected more than [time] min_step (0.0001), got '5e-05'"},
        {"[domain]\ntype = sphere\nradius = 3\nperiodic = xy\n",
         "t.ini:4: [domain] periodic: expected none for a sphere, got 'xy'"},
        {"[domain]\nperiodic = x\n[mesh]\n[domain]\ntype = sphere\n",
         "t.ini:2: [domain] periodic: expected none for a sphere, got 'x'"},
        {"[growth]\ntype = cylinder\n",
         "t.ini:2: [growth] type: expected none or planar for a plane domain, got 'cylinder'"},
        {"[domain]\ntype = sphere\n[mesh]\nlattice = hex\n", "t.ini:4: [mesh] lattice: expected random on a sphere, got 'hex'"},
        {"[mesh]\nmin_size = 20\n", "t.ini:2: [mesh] min_size: expected less than the domain size (10 cm), got '20'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        fs_config c = fs_config_default(), before = c;
        fs_error_clear();
        int rc = fs_preset_load_string(cases[i].text, "t.ini", &c);
        CHECK_MSG(rc == -1, "case %zu accepted", i);
        CHECK_MSG(fs_error_domain() == FS_ERR_DATA, "case %zu: domain %d", i, (int)fs_error_domain());
        CHECK_MSG(!strcmp(fs_error_message(), cases[i].message), "case %zu:\n  got      %s\n  expected %s", i,
                  fs_error_message(), cases[i].message);
        CHECK_MSG(config_diff(&c, &before, 0) == NULL, "case %zu changed the configuration", i);
    }
}

static void test_syntax_details(void)
{
    fs_config c = fs_config_default();
    /* Inline comments after white space, indented keys, ':' as separator, CRLF line ends, a BOM. */
    const char *text = "\xEF\xBB\xBF[mesh]\r\n  elements = 500 ; a comment\r\n\tmin_size: 0.2\r\n"
                       "[render]\ncolor_crack = #102030;not a comment\n";
    CHECK(fs_preset_load_string(text, "t", &c) == -1);
    CHECK(!strcmp(fs_error_message(),
                  "t:5: [render] color_crack: expected an sRGB colour #rrggbb, got '#102030;not a comment'"));
    c = fs_config_default();
    text = "\xEF\xBB\xBF[mesh]\r\n  elements = 500 ; a comment\r\n\tmin_size: 0.2\r\n";
    CHECK_MSG(fs_preset_load_string(text, "t", &c) == 0, "%s", fs_error_message());
    CHECK(c.mesh.elements == 500 && c.mesh.min_size == 0.2);

    /* The first error in the file is the one reported, whoever finds it. */
    CHECK(fs_preset_load_string("[mesh]\nbroken\n[mesh]\nfoo = 1\n", "t", &c) == -1);
    CHECK(!strncmp(fs_error_message(), "t:2: syntax error", 17));
    CHECK(fs_preset_load_string("[mesh]\nfoo = 1\nbroken\n", "t", &c) == -1);
    CHECK(!strncmp(fs_error_message(), "t:2: unknown key [mesh] foo", 27));

    /* Lines longer than inih's 200-byte buffer: a 255-character description is fine, 256 is not. */
    char desc[300], line[1000];
    memset(desc, 'd', 255);
    desc[255] = '\0';
    snprintf(line, sizeof line, "[preset]\n;%s\ndescription = %s ; trailing\nseed = 5\n", desc, desc);
    c = fs_config_default();
    CHECK_MSG(fs_preset_load_string(line, "t", &c) == 0, "%s", fs_error_message());
    CHECK(strlen(c.preset.description) == 255 && c.preset.seed == 5);
    snprintf(line, sizeof line, "[preset]\n\n\ndescription = %sd\n", desc);
    CHECK(fs_preset_load_string(line, "t", &c) == -1);
    CHECK(!strncmp(fs_error_message(), "t:4: [preset] description: expected at most 255 characters, got 'ddd", 67));
    snprintf(line, sizeof line, "[preset]\n%s\n", desc);
    CHECK(fs_preset_load_string(line, "t", &c) == -1);
    CHECK(!strcmp(fs_error_message(), "t:2: syntax error: expected 'key = value' or '[section]'"));
}

static void test_set(void)
{
    fs_config c = fs_config_default();
    CHECK(fs_preset_set(&c, "mesh.elements=2500") == 0 && c.mesh.elements == 2500);
    CHECK(fs_preset_set(&c, " render.size = 300x200 ") == 0 && c.render.width == 300 && c.render.height == 200);
    CHECK(fs_preset_set(&c, "preset.description=a=b") == 0 && !strcmp(c.preset.description, "a=b"));
    CHECK(fs_preset_set(&c, "material.young_map=maps/y.png") == 0 && !strcmp(c.material_files.young_map, "maps/y.png"));
    CHECK(fs_preset_set(&c, "shrink.top=0:0,1:0.5") == 0);
    CHECK_NEAR(fs_pwl_eval(&c.shrink.top, 0.5), 0.25, 1e-15);

    fs_config before = c;
    static const struct {
        const char *assignment;
        fs_errdomain domain;
        const char *message;
    } bad[] = {
        {"mesh.elements", FS_ERR_USAGE, "--set: expected SECTION.KEY=VALUE, got 'mesh.elements'"},
        {"elements=5", FS_ERR_USAGE, "--set: expected SECTION.KEY=VALUE, got 'elements=5'"},
        {".elements=5", FS_ERR_USAGE, "--set: expected SECTION.KEY=VALUE, got '.elements=5'"},
        {"a.b.c=5", FS_ERR_USAGE, "--set: expected SECTION.KEY=VALUE, got 'a.b.c=5'"},
        {"meshes.elements=5", FS_ERR_USAGE,
         "--set meshes.elements: unknown section [meshes]: expected one of: preset, domain, mesh, material, growth, "
         "shrink, fracture, time, render, voronoi, solver, wedge, springs, tet, shell"},
        {"time.stop=5", FS_ERR_USAGE, "--set time.stop: unknown key [time] stop: expected one of: end, min_step"},
        {"mesh.elements=lots", FS_ERR_DATA, "--set mesh.elements: expected an integer in 16..20000000, got 'lots'"},
        {"render.normal=up", FS_ERR_DATA, "--set render.normal: expected opengl or directx, got 'up'"},
        {"render.supersample=9", FS_ERR_DATA, "--set render.supersample: expected an integer in 1..8, got '9'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fs_error_clear();
        CHECK_MSG(fs_preset_set(&c, bad[i].assignment) == -1, "'%s' accepted", bad[i].assignment);
        CHECK_MSG(fs_error_domain() == bad[i].domain, "'%s': domain %d", bad[i].assignment, (int)fs_error_domain());
        CHECK_MSG(!strcmp(fs_error_message(), bad[i].message), "\n  got      %s\n  expected %s", fs_error_message(),
                  bad[i].message);
    }
    CHECK(config_diff(&c, &before, 0) == NULL);

    /* --set may make the whole inconsistent; fs_preset_validate names the origin. */
    CHECK(fs_preset_set(&c, "domain.type=sphere") == 0 && fs_preset_set(&c, "domain.periodic=xy") == 0);
    CHECK(fs_preset_validate(&c, "p.ini") == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK(!strcmp(fs_error_message(), "p.ini: [domain] periodic: expected none for a sphere, got 'xy'"));
    CHECK(fs_preset_set(&c, "domain.periodic=none") == 0 && fs_preset_validate(&c, "p.ini") == 0);
    CHECK(fs_preset_set(&c, "time.min_step=1") == 0 && fs_preset_validate(&c, "p.ini") == -1);
    CHECK(!strcmp(fs_error_message(), "p.ini: [time] min_step: expected less than [time] end (1), got '1'"));
}

static void test_pwl(void)
{
    fs_pwl f;
    memset(&f, 0, sizeof f);
    CHECK(fs_pwl_eval(&f, 0.5) == 0.0);
    f.n = 1;
    f.t[0] = 2;
    f.v[0] = -0.5;
    CHECK(fs_pwl_eval(&f, -10) == -0.5 && fs_pwl_eval(&f, 10) == -0.5);
    f.n = 3;
    f.t[1] = 4;
    f.v[1] = 1.5;
    f.t[2] = 5;
    f.v[2] = 0.5;
    CHECK(fs_pwl_eval(&f, 1) == -0.5);
    CHECK(fs_pwl_eval(&f, 2) == -0.5);
    CHECK(fs_pwl_eval(&f, 4) == 1.5);
    CHECK(fs_pwl_eval(&f, 5) == 0.5 && fs_pwl_eval(&f, 6) == 0.5);
    CHECK_NEAR(fs_pwl_eval(&f, 3), 0.5, 1e-15);
    CHECK_NEAR(fs_pwl_eval(&f, 3.5), 1.0, 1e-15);
    CHECK_NEAR(fs_pwl_eval(&f, 4.25), 1.25, 1e-15);
}

static void test_color_round_trip(void)
{
    /* Every 8-bit sRGB value decodes to a distinct float that encodes back to itself. */
    int failures = 0;
    float prev = -1.0f;
    for (int v = 0; v < 256; v++) {
        char assign[64], hex[8];
        snprintf(hex, sizeof hex, "#%02x%02x%02x", v, 255 - v, (v * 7) & 255);
        snprintf(assign, sizeof assign, "render.color_crack=%s", hex);
        fs_config c = fs_config_default();
        if (fs_preset_set(&c, assign) != 0) {
            failures++;
            continue;
        }
        if (!(c.render.color_crack[0] > prev))
            failures++;
        prev = c.render.color_crack[0];
        char *text = dump_string(&c);
        char want[40];
        snprintf(want, sizeof want, "\ncolor_crack = %s\n", hex);
        if (!strstr(text, want))
            failures++;
        free(text);
    }
    CHECK(failures == 0);
    fs_config c = fs_config_default();
    CHECK(fs_preset_set(&c, "render.color_material=#ffffff") == 0 && c.render.color_material[1] == 1.0f);
    CHECK(fs_preset_set(&c, "render.color_material=#0A0a0A") == 0);
    CHECK_NEAR(c.render.color_material[0], 10.0 / 255.0 / 12.92, 1e-7);
}

static void test_file_load(void)
{
    char dir[] = "/tmp/fissure-test-preset-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char sub[128], path[160], missing[160];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    mkdir(sub, 0700);
    snprintf(path, sizeof path, "%s/p.ini", sub);
    write_file(path, "[material]\nthickness_map = ../textures/ramp.png\nyoung_map = /abs/y.png\n");
    fs_config c = fs_config_default();
    CHECK_MSG(fs_preset_load(path, &c) == 0, "%s", fs_error_message());
    char want[400];
    snprintf(want, sizeof want, "%s/../textures/ramp.png", sub);
    CHECK_MSG(!strcmp(c.material_files.thickness_map, want), "%s", c.material_files.thickness_map);
    CHECK(!strcmp(c.material_files.young_map, "/abs/y.png"));

    /* Resolved paths survive a dump and reload from anywhere. */
    char *text = dump_string(&c);
    char path2[160];
    snprintf(path2, sizeof path2, "%s/dump.ini", dir);
    write_file(path2, text);
    fs_config d = fs_config_default();
    CHECK(fs_preset_load(path2, &d) == 0);
    CHECK(!strcmp(d.material_files.thickness_map, want));
    free(text);

    /* A missing file is FS_ERR_NOINPUT; an error inside a file names it with its line. */
    snprintf(missing, sizeof missing, "%s/missing.ini", dir);
    CHECK(fs_preset_load(missing, &c) == -1 && fs_error_domain() == FS_ERR_NOINPUT);
    snprintf(want, sizeof want, "%s: cannot open preset: No such file or directory", missing);
    CHECK(!strcmp(fs_error_message(), want));
    CHECK(fs_preset_load(dir, &c) == -1 && fs_error_domain() == FS_ERR_NOINPUT);
    write_file(path2, "[preset]\nname = x\n\nmodel = fem\n");
    CHECK(fs_preset_load(path2, &c) == -1 && fs_error_domain() == FS_ERR_DATA);
    snprintf(want, sizeof want, "%s:4: [preset] model: expected voronoi, springs, wedge, shell or tet, got 'fem'",
             path2);
    CHECK(!strcmp(fs_error_message(), want));

    unlink(path);
    unlink(path2);
    rmdir(sub);
    rmdir(dir);
}

static void test_preset_path(void)
{
    char base[] = "/tmp/fissure-test-path-XXXXXX";
    CHECK(mkdtemp(base) != NULL);
    char d1[128], d2[128], xdg[128], env[300], p[400];
    snprintf(d1, sizeof d1, "%s/one", base);
    snprintf(d2, sizeof d2, "%s/two", base);
    snprintf(xdg, sizeof xdg, "%s/xdg", base);
    mkdir(d1, 0700);
    mkdir(d2, 0700);
    mkdir(xdg, 0700);
    static const char *const files[][2] = {
        {"one/alpha.ini", "[preset]\ndescription = first alpha\n"},
        {"two/alpha.ini", "[preset]\ndescription = shadowed alpha\n"},
        {"two/beta.ini", "[preset]\nname = b\ndescription = the beta preset\n"},
        {"two/broken.ini", "[preset]\n\ncolour = red\n"},
        {"two/notes.txt", "not a preset\n"},
    };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", base, files[i][0]);
        write_file(p, files[i][1]);
    }
    snprintf(env, sizeof env, "%s::%s", d1, d2);
    setenv("FISSURE_PRESET_PATH", env, 1);
    setenv("XDG_DATA_HOME", xdg, 1);

    char *found = fs_preset_find("alpha");
    snprintf(p, sizeof p, "%s/alpha.ini", d1);
    CHECK(found && !strcmp(found, p));
    free(found);
    found = fs_preset_find("beta.ini");
    snprintf(p, sizeof p, "%s/beta.ini", d2);
    CHECK(found && !strcmp(found, p));
    free(found);
    /* An existing path is used as it is. */
    found = fs_preset_find(p);
    CHECK(found && !strcmp(found, p));
    free(found);
    fs_error_clear();
    CHECK(fs_preset_find("gamma") == NULL && fs_error_domain() == FS_ERR_NOINPUT);
    CHECK(strstr(fs_error_message(), "gamma: cannot open preset") && strstr(fs_error_message(), d1) &&
          strstr(fs_error_message(), xdg));
    CHECK(fs_preset_find("nowhere/alpha.ini") == NULL && fs_error_domain() == FS_ERR_NOINPUT);

    char *text = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&text, &size);
    int n = fs_preset_list(out);
    fclose(out);
    CHECK(n >= 3);
    char *a = strstr(text, "alpha\tfirst alpha\n");
    char *b = strstr(text, "\nb\tthe beta preset\n");
    snprintf(p, sizeof p, "broken\t(unreadable: %s/broken.ini:3: unknown key [preset] colour: expected one of: ", d2);
    char *c = strstr(text, p);
    CHECK_MSG(a && b && c && a < b && b < c, "%s", text);
    CHECK(strstr(text, "shadowed") == NULL && strstr(text, "notes") == NULL);
    /* The name listed finds the preset too. */
    found = fs_preset_find("b");
    snprintf(p, sizeof p, "%s/beta.ini", d2);
    CHECK(found && !strcmp(found, p));
    free(found);
    CHECK(fs_error_domain() == FS_OK);
    free(text);

    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", base, files[i][0]);
        unlink(p);
    }
    rmdir(d1);
    rmdir(d2);
    rmdir(xdg);
    rmdir(base);
    unsetenv("FISSURE_PRESET_PATH");
}

/* Numbers are decimal: hexadecimal floats and integers, which strtod reads, are refused. */
static void test_decimal_only(void)
{
    static const char *const bad[] = {"0x10", "0x1p3", "0X1P-2", "-0x8", "1e", ".", "+.", "e5", "1.5.2", "infinity"};
    static const char *const good[] = {"16", "8.", ".5", "+2", "-3e+2", "1E-3", "0.25e1"};
    char assignment[64];
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        fs_config c = fs_config_default();
        snprintf(assignment, sizeof assignment, "voronoi.warp_scale=%s", bad[i]);
        fs_error_clear();
        CHECK_MSG(fs_preset_set(&c, assignment) == -1 && fs_error_domain() == FS_ERR_DATA, "%s accepted", bad[i]);
    }
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        fs_config c = fs_config_default();
        snprintf(assignment, sizeof assignment, "growth.rate=%s", good[i]);
        CHECK_MSG(fs_preset_set(&c, assignment) == 0, "%s: %s", good[i], fs_error_message());
        CHECK_NEAR(c.growth.rate, strtod(good[i], NULL), 0.0);
    }
    fs_config c = fs_config_default();
    CHECK(fs_preset_load_string("[mesh]\nelements = 0x10\n", "t.ini", &c) == -1);
    CHECK(fs_preset_load_string("[shrink]\ntop = 0:0, 0x1p0:0.1\n", "t.ini", &c) == -1);
}

/* Every text and path value the parser accepts survives the dump: a value starting with ';' would
 * come back as a comment after the dump's "key = ", so it is refused; '#' is kept. */
static void test_text_round_trip(void)
{
    fs_config c = fs_config_default();
    fs_error_clear();
    CHECK(fs_preset_load_string("[preset]\ndescription =;x\n", "t.ini", &c) == -1);
    CHECK_MSG(strstr(fs_error_message(), "t.ini:2: [preset] description: expected one line without control "
                                         "characters, a leading ';' or ' ;' (a comment), got ';x'") != NULL,
              "%s", fs_error_message());
    CHECK(fs_preset_set(&c, "material.young_map=;y.png") == -1);
    CHECK(fs_preset_load_string("[preset]\ndescription =#x; y;z\n[material]\nyoung_map = #y.png\n", "t.ini",
                                &c) == 0);
    char *text = dump_string(&c);
    fs_config d = fs_config_default();
    CHECK(fs_preset_load_string(text, "dump", &d) == 0);
    CHECK(!strcmp(d.preset.description, "#x; y;z") && !strcmp(d.material_files.young_map, "#y.png"));
    char *again = dump_string(&d);
    CHECK(!strcmp(text, again));
    free(text);
    free(again);
}

/* Presets are at most 1 MiB: a larger file is bad data, refused without reading it all, and a line
 * with a NUL byte is a syntax error. (A FIFO and a device, which used to block or never end, are
 * tried in tests/cli_hostile.sh under a timeout.) */
static void test_file_limits(void)
{
    char dir[] = "/tmp/fissure-test-preset-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char big[160], nul[160];
    snprintf(big, sizeof big, "%s/big.ini", dir);
    snprintf(nul, sizeof nul, "%s/nul.ini", dir);
    fs_config c = fs_config_default();
    /* a comment line of 1 MiB + 1 byte: over the cap by its size */
    FILE *f = fopen(big, "w");
    CHECK(f != NULL);
    if (f) {
        fputc('#', f);
        for (int i = 0; i < 1024 * 1024; i++)
            fputc('a', f);
        fclose(f);
    }
    fs_error_clear();
    CHECK(fs_preset_load(big, &c) == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "expected at most 1048576 bytes (1 MiB)") != NULL, "%s", fs_error_message());
    CHECK(fs_preset_read_text(big) == NULL);
    f = fopen(nul, "w");
    if (f) {
        static const char text[] = "[preset]\nname = a\nseed = 5\0001\n";
        fwrite(text, 1, sizeof text - 1, f);
        fclose(f);
    }
    fs_error_clear();
    CHECK(fs_preset_load(nul, &c) == -1 && fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "nul.ini:3: syntax error") != NULL, "%s", fs_error_message());
    char *text = fs_preset_read_text(nul);
    CHECK(text && !strncmp(text, "[preset]", 8));
    free(text);
    unlink(big);
    unlink(nul);
    rmdir(dir);
}

int main(void)
{
    RUN(test_defaults);
    RUN(test_full_preset);
    RUN(test_default_round_trip);
    RUN(test_errors);
    RUN(test_syntax_details);
    RUN(test_set);
    RUN(test_pwl);
    RUN(test_color_round_trip);
    RUN(test_file_load);
    RUN(test_preset_path);
    RUN(test_decimal_only);
    RUN(test_text_round_trip);
    RUN(test_file_limits);
    return check_finish();
}
