/* Engine targets (--target): per engine, each map's file name, packing, normal convention and colour tag. */
#ifndef FS_IO_TARGET_H
#define FS_IO_TARGET_H

#include <stdbool.h>

#include "image/image.h"
#include "io/output.h"
#include "io/sidecar.h"
#include "render/crackgraph.h"
#include "render/render.h"

typedef enum {
    FS_TARGET_GENERIC = 0, /* NAME_KIND.png, normal convention from the preset or --normal */
    FS_TARGET_GLTF,        /* glTF 2.0 materials: OpenGL normals, occlusion-roughness-metallic map */
    FS_TARGET_UNREAL,      /* Unreal Engine: DirectX normals, T_NAME_BC / _N / _ORM */
    FS_TARGET_UNITY_HDRP,  /* Unity HDRP Lit: OpenGL normals, mask map (metallic, AO, detail, smoothness) */
    FS_TARGET_BLENDER,     /* Blender (Node Wrangler names): OpenGL normals, separate AO and roughness */
    FS_TARGET_COUNT
} fs_target;

/* The word of --target ("generic", "gltf", "unreal", "unity-hdrp", "blender"); parse returns 0,
 * or -1 for an unknown word (the caller reports it). */
const char *fs_target_name(fs_target t);
int fs_target_parse(const char *word, fs_target *out);

/* Whether the engine dictates the normal convention (every target but generic), and which. */
bool fs_target_fixes_normal(fs_target t);
fs_normal_convention fs_target_normal(fs_target t);

/* What the maps are written from. Pointers are borrowed; an image is needed only when its kind
 * is written. */
typedef struct {
    const fs_maps *maps;
    const fs_image *height;        /* the height map to write: &maps->height, or float cm for EXR */
    const char *height_ext;        /* "png" or "exr" */
    const fs_image *preview;       /* the lit preview */
    const fs_image *occlusion;     /* 1 x u8 ambient occlusion, 255 = open (render/occlusion.h) */
    double roughness;              /* [render] roughness, in [0, 1], for packed maps */
    fs_normal_convention normal;   /* the convention the normal map was built with */
    const fs_crackgraph *cracks;   /* the crack graph */
} fs_target_inputs;

#define FS_TARGET_MAX_FILES 32

/* The files written, for the sidecar and for stdout. Owns the packed images. */
typedef struct {
    int n;
    fs_sidecar_map map[FS_TARGET_MAX_FILES];
    char file[FS_TARGET_MAX_FILES][512];
    fs_image packed[FS_TARGET_MAX_FILES];
} fs_target_output;

/* Stages and writes, in out, the files of each map kind in kinds (height, normal, basecolor,
 * crackmask, crackdist, cellid, preview, occlusion, cracks) as target t names and packs them, for
 * output name `name`:
 *
 *   kind       generic         gltf                   unreal     unity-hdrp      blender
 *   basecolor  NAME_basecolor  NAME_baseColor         T_NAME_BC  NAME_BaseColor  NAME_basecolor
 *   normal     NAME_normal     NAME_normal            T_NAME_N   NAME_Normal     NAME_normal
 *   height     NAME_height     NAME_height            T_NAME_H   NAME_Height     NAME_height
 *   occlusion  NAME_occlusion  NAME_occlusion-        T_NAME_ORM NAME_MaskMap    NAME_ao and
 *                              RoughnessMetallic                                 NAME_roughness
 * crackmask, crackdist and cellid keep NAME_KIND but for unreal (T_NAME_CrackMask, T_NAME_CrackDist,
 * T_NAME_CellID); the preview is NAME_preview, the crack graph NAME_cracks.json and .svg. Normals
 * are OpenGL (+Y) but for unreal (DirectX) and generic (the preset's or --normal's).
 *
 * Packed maps: ORM = R occlusion, G roughness, B metallic 0 (gltf, unreal); MaskMap = R metallic 0,
 * G occlusion, B detail mask = crack mask, A smoothness = 1 - roughness (unity-hdrp). Colour maps
 * (basecolor, preview) carry an sRGB chunk, every other PNG none. Each file's sidecar entry says
 * its colour space, what each channel holds and how the engine uses it. Returns 0, or -1 with
 * fs_error (files already staged are left to the caller's fs_output_abort). */
int fs_target_write(fs_output *out, fs_target t, const char *name, const char *const *kinds, int n_kinds,
                    const fs_target_inputs *in, fs_target_output *written);
/* Frees the packed images (the file names stay valid). */
void fs_target_output_free(fs_target_output *w);

#endif
