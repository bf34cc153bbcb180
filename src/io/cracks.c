/* The crack graph as JSON (jansson, as the sidecar) and as SVG (plain text). */
#include "io/cracks.h"

#include "config.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"

static const char *const kind_names[] = {"junction", "end", "border"};

/* Texture coordinates rounded to 1e-7 (a hundredth of a pixel up to 100000 pixels), so the file
 * holds short decimals rather than binary noise. */
static json_t *coord(double x)
{
    return json_real(round(x * 1e7) / 1e7);
}

static json_t *uv_pair(const double *uv)
{
    json_t *a = json_array();
    json_array_append_new(a, coord(uv[0]));
    json_array_append_new(a, coord(uv[1]));
    return a;
}

static json_t *node_ref(int32_t n)
{
    return n >= 0 ? json_integer(n) : json_null();
}

static json_t *summary(const fs_crackgraph *g)
{
    int32_t counts[3] = {0, 0, 0}, max_degree = 0;
    for (int32_t i = 0; i < g->n_nodes; i++) {
        counts[g->node[i].kind]++;
        if (g->node[i].degree > max_degree)
            max_degree = g->node[i].degree;
    }
    json_t *s = json_object();
    json_object_set_new(s, "junctions", json_integer(counts[FS_CRACK_JUNCTION]));
    json_object_set_new(s, "ends", json_integer(counts[FS_CRACK_END]));
    json_object_set_new(s, "border_ends", json_integer(counts[FS_CRACK_BORDER]));
    json_object_set_new(s, "cracks", json_integer(g->n_edges));
    json_object_set_new(s, "fragments", json_integer(g->n_fragments));
    json_object_set_new(s, "adjacent_pairs", json_integer(g->n_adjacent));
    double length = 0.0;
    for (int32_t i = 0; i < g->n_edges; i++)
        length += g->edge[i].length;
    json_object_set_new(s, "total_length_px", json_real(round(length * 100.0) / 100.0));
    json_t *by_degree = json_object();
    for (int32_t d = 3; d <= max_degree; d++) {
        int32_t n = 0;
        for (int32_t i = 0; i < g->n_nodes; i++)
            n += g->node[i].kind == FS_CRACK_JUNCTION && g->node[i].degree == d;
        if (n) {
            char key[16];
            snprintf(key, sizeof key, "%d", (int)d);
            json_object_set_new(by_degree, key, json_integer(n));
        }
    }
    json_object_set_new(s, "junction_degrees", by_degree);
    return s;
}

static json_t *edge_entry(const fs_crackgraph *g, int32_t i)
{
    const fs_crack_edge *e = &g->edge[i];
    json_t *o = json_object();
    json_object_set_new(o, "id", json_integer(i));
    bool closed = e->node[0] < 0;
    json_t *nodes = json_array();
    json_array_append_new(nodes, node_ref(e->node[0]));
    json_array_append_new(nodes, node_ref(e->node[1]));
    json_object_set_new(o, "nodes", nodes);
    json_object_set_new(o, "closed", json_boolean(closed));
    json_object_set_new(o, "length_px", json_real(round(e->length * 100.0) / 100.0));
    json_object_set_new(o, "width_px", json_real(round(e->width * 100.0) / 100.0));
    json_object_set_new(o, "left", json_integer(e->left));
    json_object_set_new(o, "right", json_integer(e->right));
    json_t *pieces = json_array();
    for (int32_t k = e->first_piece; k < e->first_piece + e->n_pieces; k++) {
        json_t *piece = json_array();
        for (int32_t q = g->piece_start[k]; q < g->piece_start[k + 1]; q++)
            json_array_append_new(piece, uv_pair(g->point + 2 * q));
        json_array_append_new(pieces, piece);
    }
    json_object_set_new(o, "polylines", pieces);
    return o;
}

/* Fragments with their neighbours, gathered per fragment from the adjacent pairs (sorted by a, b,
 * so each neighbour list comes out in increasing order). */
static json_t *fragments(const fs_crackgraph *g)
{
    int32_t *index = fs_malloc(65536 * sizeof *index);
    for (int i = 0; i < 65536; i++)
        index[i] = -1;
    for (int32_t i = 0; i < g->n_fragments; i++)
        index[g->fragment[i].id] = i;
    json_t **nb = fs_calloc((size_t)g->n_fragments + 1, sizeof *nb);
    for (int32_t i = 0; i < g->n_fragments; i++)
        nb[i] = json_array();
    for (int pass = 0; pass < 2; pass++)
        for (int32_t k = 0; k < g->n_adjacent; k++) {
            const fs_crack_adjacency *a = &g->adjacent[k];
            int32_t ia = index[a->a], ib = index[a->b];
            if (pass == 0 && ib >= 0)
                json_array_append_new(nb[ib], json_integer(a->a));
            if (pass == 1 && ia >= 0)
                json_array_append_new(nb[ia], json_integer(a->b));
        }
    json_t *list = json_array();
    for (int32_t i = 0; i < g->n_fragments; i++) {
        const fs_crack_fragment *f = &g->fragment[i];
        json_t *o = json_object();
        json_object_set_new(o, "id", json_integer(f->id));
        json_object_set_new(o, "area_px", json_integer(f->area));
        json_object_set_new(o, "centroid", uv_pair(f->centroid));
        json_object_set_new(o, "neighbours", nb[i]);
        json_array_append_new(list, o);
    }
    free(nb);
    free(index);
    return list;
}

int fs_cracks_write_json(const char *path, const fs_crackgraph *g)
{
    json_t *root = json_object();
    json_object_set_new(root, "generator", json_string("fissure"));
    json_object_set_new(root, "version", json_string(PACKAGE_VERSION));
    json_object_set_new(root, "width", json_integer(g->width));
    json_object_set_new(root, "height", json_integer(g->height));
    json_t *tile = json_object();
    json_object_set_new(tile, "u", json_boolean(g->wrap_u));
    json_object_set_new(tile, "v", json_boolean(g->wrap_v));
    json_object_set_new(root, "tileable", tile);
    json_object_set_new(root, "coordinates",
                        json_string("texture space [u, v] in [0, 1], u to the right, v up; pixel (i, j) of the "
                                    "maps has its centre at ((i + 0.5) / width, 1 - (j + 0.5) / height). A "
                                    "polyline ending on a tileable edge continues as the next polyline of its "
                                    "crack from the opposite edge."));
    json_object_set_new(root, "summary", summary(g));

    json_t *nodes = json_array();
    for (int32_t i = 0; i < g->n_nodes; i++) {
        json_t *o = json_object();
        json_object_set_new(o, "id", json_integer(i));
        json_object_set_new(o, "uv", uv_pair(g->node[i].uv));
        json_object_set_new(o, "degree", json_integer(g->node[i].degree));
        json_object_set_new(o, "kind", json_string(kind_names[g->node[i].kind]));
        json_array_append_new(nodes, o);
    }
    json_object_set_new(root, "nodes", nodes);
    json_t *edges = json_array();
    for (int32_t i = 0; i < g->n_edges; i++)
        json_array_append_new(edges, edge_entry(g, i));
    json_object_set_new(root, "cracks", edges);
    json_object_set_new(root, "fragments", fragments(g));
    json_t *adj = json_array();
    for (int32_t k = 0; k < g->n_adjacent; k++) {
        json_t *o = json_object();
        json_t *pair = json_array();
        json_array_append_new(pair, json_integer(g->adjacent[k].a));
        json_array_append_new(pair, json_integer(g->adjacent[k].b));
        json_object_set_new(o, "fragments", pair);
        json_object_set_new(o, "contact_px", json_integer(g->adjacent[k].contact));
        json_array_append_new(adj, o);
    }
    json_object_set_new(root, "adjacency", adj);

    errno = 0;
    int rc = json_dump_file(root, path, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    int err = errno;
    json_decref(root);
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
