/* The resolved configuration of one run: what a preset (plus overrides) becomes, section by section. */
#ifndef FS_SIM_SETTINGS_H
#define FS_SIM_SETTINGS_H

#include <stdint.h>

#include "field/field.h"
#include "geom/domain.h"
#include "model/model.h"
#include "render/render.h"

/* Longest file path a preset may give (a map image). */
#define FS_PATH_MAX 1024

typedef struct {
    char name[64];          /* short name, used as the default output name */
    char description[256];  /* one line shown by --list-presets */
    fs_model_kind model;
    uint64_t seed;          /* random seed (the command line's --seed overrides it) */
} fs_preset_info;

/* The grey-level images of [material] (thesis §5.9), resolved against the preset's directory; "" for
 * none. sim loads them into the model's maps (fs_model_setup). */
typedef struct {
    char thickness_map[FS_PATH_MAX]; /* scales the thickness */
    char young_map[FS_PATH_MAX];     /* scales Young's modulus */
    char threshold_map[FS_PATH_MAX]; /* scales the threshold stress */
} fs_material_files;

/* One struct per preset section, each from its module's defaults function. */
typedef struct {
    fs_preset_info preset;
    fs_domain domain;
    char domain_file[FS_PATH_MAX]; /* [domain] file: the UV-mapped OBJ of a mesh domain, resolved against
                                      the preset's directory; "" for none */
    fs_mesh_params mesh;
    fs_material material;
    fs_material_files material_files;
    fs_growth growth;
    fs_shrink shrink;
    fs_fracture_params fracture;
    fs_time_params time;
    fs_render_params render;
    fs_voronoi_params voronoi;
    fs_springs_params springs;
    fs_solver_params solver;
    fs_wedge_params wedge;
    fs_tet_params tet;
    fs_shell_params shell;
} fs_config;

/* Every section at its default: a 10 x 10 cm non-periodic plane, voronoi model, 1000 elements. */
fs_config fs_config_default(void);

/* The model's view of cfg: its sections copied, the maps left empty (sim loads them). */
fs_model_setup fs_config_model_setup(const fs_config *cfg);

#endif
