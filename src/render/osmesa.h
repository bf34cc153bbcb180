/* OSMesa context for off-screen rendering (osmesa.c is the only file that includes OSMesa). */
#ifndef FS_RENDER_OSMESA_H
#define FS_RENDER_OSMESA_H
#endif
