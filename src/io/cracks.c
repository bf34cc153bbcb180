/* The crack graph as JSON (io/json.h, as the sidecar) and as SVG (plain text). */
#include "io/cracks.h"

#include "config.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "io/json.h"

static const char *const kind_names[] = {"junction", "end", "border"};

/* Texture coordinates rounded to 1e-7 (a hundredth of a pixel up to 100000 pixels), so the file
 * holds short decimals rather than binary noise. */
static fs_json *coord(double x)
{
    return fs_json_real(round(x * 1e7) / 1e7);
}

static fs_json *uv_pair(const double *uv)
{
    fs_json *a = fs_json_array();
    fs_json_append(a, coord(uv[0]));
    fs_json_append(a, coord(uv[1]));
    return a;
}

static fs_json *node_ref(int32_t n)
{
    return n >= 0 ? fs_json_integer(n) : fs_json_null();
}

static fs_json *summary(const fs_crackgraph *g)
{
    int32_t counts[3] = {0, 0, 0}, max_degree = 0;
    for (int32_t i = 0; i < g->n_nodes; i++) {
        counts[g->node[i].kind]++;
        if (g->node[i].degree > max_degree)
            max_degree = g->node[i].degree;
    }
    fs_json *s = fs_json_object();
    fs_json_set(s, "junctions", fs_json_integer(counts[FS_CRACK_JUNCTION]));
    fs_json_set(s, "ends", fs_json_integer(counts[FS_CRACK_END]));
    fs_json_set(s, "border_ends", fs_json_integer(counts[FS_CRACK_BORDER]));
    fs_json_set(s, "cracks", fs_json_integer(g->n_edges));
    fs_json_set(s, "fragments", fs_json_integer(g->n_fragments));
    fs_json_set(s, "adjacent_pairs", fs_json_integer(g->n_adjacent));
    double length = 0.0;
    for (int32_t i = 0; i < g->n_edges; i++)
        length += g->edge[i].length;
    fs_json_set(s, "total_length_px", fs_json_real(round(length * 100.0) / 100.0));
    fs_json *by_degree = fs_json_object();
    for (int32_t d = 3; d <= max_degree; d++) {
        int32_t n = 0;
        for (int32_t i = 0; i < g->n_nodes; i++)
            n += g->node[i].kind == FS_CRACK_JUNCTION && g->node[i].degree == d;
        if (n) {
            char key[16];
            snprintf(key, sizeof key, "%d", (int)d);
            fs_json_set(by_degree, key, fs_json_integer(n));
        }
    }
    fs_json_set(s, "junction_degrees", by_degree);
    return s;
}

static fs_json *edge_entry(const fs_crackgraph *g, int32_t i)
{
    const fs_crack_edge *e = &g->edge[i];
    fs_json *o = fs_json_object();
    fs_json_set(o, "id", fs_json_integer(i));
    bool closed = e->node[0] < 0;
    fs_json *nodes = fs_json_array();
    fs_json_append(nodes, node_ref(e->node[0]));
    fs_json_append(nodes, node_ref(e->node[1]));
    fs_json_set(o, "nodes", nodes);
    fs_json_set(o, "closed", fs_json_bool(closed));
    fs_json_set(o, "length_px", fs_json_real(round(e->length * 100.0) / 100.0));
    fs_json_set(o, "width_px", fs_json_real(round(e->width * 100.0) / 100.0));
    fs_json_set(o, "left", fs_json_integer(e->left));
    fs_json_set(o, "right", fs_json_integer(e->right));
    fs_json *pieces = fs_json_array();
    for (int32_t k = e->first_piece; k < e->first_piece + e->n_pieces; k++) {
        fs_json *piece = fs_json_array();
        for (int32_t q = g->piece_start[k]; q < g->piece_start[k + 1]; q++)
            fs_json_append(piece, uv_pair(g->point + 2 * q));
        fs_json_append(pieces, piece);
    }
    fs_json_set(o, "polylines", pieces);
    return o;
}

/* Fragments with their neighbours, gathered per fragment from the adjacent pairs (sorted by a, b,
 * so each neighbour list comes out in increasing order). */
static fs_json *fragments(const fs_crackgraph *g)
{
    int32_t *index = fs_malloc(65536 * sizeof *index);
    for (int i = 0; i < 65536; i++)
        index[i] = -1;
    for (int32_t i = 0; i < g->n_fragments; i++)
        index[g->fragment[i].id] = i;
    fs_json **nb = fs_calloc((size_t)g->n_fragments + 1, sizeof *nb);
    for (int32_t i = 0; i < g->n_fragments; i++)
        nb[i] = fs_json_array();
    for (int pass = 0; pass < 2; pass++)
        for (int32_t k = 0; k < g->n_adjacent; k++) {
            const fs_crack_adjacency *a = &g->adjacent[k];
            int32_t ia = index[a->a], ib = index[a->b];
            if (pass == 0 && ib >= 0)
                fs_json_append(nb[ib], fs_json_integer(a->a));
            if (pass == 1 && ia >= 0)
                fs_json_append(nb[ia], fs_json_integer(a->b));
        }
    fs_json *list = fs_json_array();
    for (int32_t i = 0; i < g->n_fragments; i++) {
        const fs_crack_fragment *f = &g->fragment[i];
        fs_json *o = fs_json_object();
        fs_json_set(o, "id", fs_json_integer(f->id));
        fs_json_set(o, "area_px", fs_json_integer(f->area));
        fs_json_set(o, "centroid", uv_pair(f->centroid));
        fs_json_set(o, "neighbours", nb[i]);
        fs_json_append(list, o);
    }
    free(nb);
    free(index);
    return list;
}

int fs_cracks_write_json(const char *path, const fs_crackgraph *g)
{
    fs_json *root = fs_json_object();
    fs_json_set(root, "generator", fs_json_string("fissure"));
    fs_json_set(root, "version", fs_json_string(PACKAGE_VERSION));
    fs_json_set(root, "width", fs_json_integer(g->width));
    fs_json_set(root, "height", fs_json_integer(g->height));
    fs_json *tile = fs_json_object();
    fs_json_set(tile, "u", fs_json_bool(g->wrap_u));
    fs_json_set(tile, "v", fs_json_bool(g->wrap_v));
    fs_json_set(root, "tileable", tile);
    fs_json_set(root, "coordinates",
                        fs_json_string("texture space [u, v] in [0, 1], u to the right, v up; pixel (i, j) of the "
                                    "maps has its centre at ((i + 0.5) / width, 1 - (j + 0.5) / height). A "
                                    "polyline ending on a tileable edge continues as the next polyline of its "
                                    "crack from the opposite edge."));
    fs_json_set(root, "summary", summary(g));

    fs_json *nodes = fs_json_array();
    for (int32_t i = 0; i < g->n_nodes; i++) {
        fs_json *o = fs_json_object();
        fs_json_set(o, "id", fs_json_integer(i));
        fs_json_set(o, "uv", uv_pair(g->node[i].uv));
        fs_json_set(o, "degree", fs_json_integer(g->node[i].degree));
        fs_json_set(o, "kind", fs_json_string(kind_names[g->node[i].kind]));
        fs_json_append(nodes, o);
    }
    fs_json_set(root, "nodes", nodes);
    fs_json *edges = fs_json_array();
    for (int32_t i = 0; i < g->n_edges; i++)
        fs_json_append(edges, edge_entry(g, i));
    fs_json_set(root, "cracks", edges);
    fs_json_set(root, "fragments", fragments(g));
    fs_json *adj = fs_json_array();
    for (int32_t k = 0; k < g->n_adjacent; k++) {
        fs_json *o = fs_json_object();
        fs_json *pair = fs_json_array();
        fs_json_append(pair, fs_json_integer(g->adjacent[k].a));
        fs_json_append(pair, fs_json_integer(g->adjacent[k].b));
        fs_json_set(o, "fragments", pair);
        fs_json_set(o, "contact_px", fs_json_integer(g->adjacent[k].contact));
        fs_json_append(adj, o);
    }
    fs_json_set(root, "adjacency", adj);

    errno = 0;
    int rc = fs_json_write(root, path, (fs_json_format){1, 10});
    int err = errno;
    fs_json_free(root);
    if (rc != 0) {
        fs_error(FS_ERR_IO, "%s: cannot write the crack graph: %s", path, strerror(err ? err : EIO));
        return -1;
    }
    return 0;
}

static const char *node_colour(const fs_crack_node *n)
{
    switch (n->kind) {
    case FS_CRACK_JUNCTION: return n->degree == 3 ? "#d62728" : "#9467bd";
    case FS_CRACK_END: return "#1f77b4";
    case FS_CRACK_BORDER: return "#2ca02c";
    }
    return "#000000";
}

int fs_cracks_write_svg(const char *path, const fs_crackgraph *g)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot write the crack graph: %s", path, strerror(errno));
        return -1;
    }
    const double w = g->width, h = g->height;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n",
            g->width, g->height, g->width, g->height);
    fprintf(f, "<title>fissure %s crack graph</title>\n", PACKAGE_VERSION);
    fprintf(f, "<desc>Crack centre lines in map pixels (y down, overlaying the maps): %d cracks, %d nodes, "
               "%d fragments.</desc>\n",
            (int)g->n_edges, (int)g->n_nodes, (int)g->n_fragments);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#ffffff\"/>\n", g->width, g->height);
    fprintf(f, "<g fill=\"none\" stroke=\"#000000\" stroke-linecap=\"round\" stroke-linejoin=\"round\">\n");
    for (int32_t i = 0; i < g->n_edges; i++) {
        const fs_crack_edge *e = &g->edge[i];
        double sw = e->width > 1.0 ? e->width : 1.0;
        for (int32_t k = e->first_piece; k < e->first_piece + e->n_pieces; k++) {
            fprintf(f, "<polyline stroke-width=\"%.2f\" points=\"", sw);
            for (int32_t q = g->piece_start[k]; q < g->piece_start[k + 1]; q++)
                fprintf(f, "%s%.2f,%.2f", q > g->piece_start[k] ? " " : "", g->point[2 * q] * w,
                        (1.0 - g->point[2 * q + 1]) * h);
            fprintf(f, "\"/>\n");
        }
    }
    fprintf(f, "</g>\n<g stroke=\"none\">\n");
    for (int32_t i = 0; i < g->n_nodes; i++) {
        const fs_crack_node *n = &g->node[i];
        fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.1f\" fill=\"%s\"/>\n", n->uv[0] * w, (1.0 - n->uv[1]) * h,
                n->kind == FS_CRACK_JUNCTION ? 2.5 : 2.0, node_colour(n));
    }
    fprintf(f, "</g>\n</svg>\n");
    return fs_close_written(f, path, "the crack graph");
}
