/* Writers of the crack graph (render/crackgraph.h): NAME_cracks.json (io/json.h) and NAME_cracks.svg. */
#ifndef FS_IO_CRACKS_H
#define FS_IO_CRACKS_H

#include "render/crackgraph.h"

/* Writes the graph as JSON to exactly path: map size and tileability, a summary (counts, junctions
 * by degree), nodes (texture position, degree, kind), cracks (end nodes or closed, length and mean
 * width in pixels, left and right fragment, centre line pieces in [0, 1]^2 with v up), fragments
 * (id, area in pixels, centroid, neighbours) and adjacent fragment pairs (contact in pixels).
 * Returns 0 or -1 with fs_error(FS_ERR_IO). */
int fs_cracks_write_json(const char *path, const fs_crackgraph *g);

/* Writes the graph as a standalone SVG drawing to exactly path, in pixels of the map (y down, so
 * it overlays the PNG maps): centre lines stroked with their mean width, junctions red (degree 3)
 * or purple (degree 4 and more), crack tips blue, border ends green. Returns 0 or -1 with
 * fs_error(FS_ERR_IO). */
int fs_cracks_write_svg(const char *path, const fs_crackgraph *g);

#endif
