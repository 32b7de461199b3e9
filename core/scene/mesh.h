/* Closed triangle meshes (Wavefront OBJ) as solids.
 *
 * A mesh is loaded once and then only queried; every query is const and
 * thread-safe (OpenMP callers may share one Mesh).
 *
 * Inside/outside is decided by the generalized winding number (Jacobson et
 * al. 2013): the sum of the solid angles of all triangles seen from the
 * point, divided by 4 pi. It is 1 inside and 0 outside a closed mesh and
 * degrades gracefully (a smooth value near 1/2 across holes) on nearly closed
 * ones. It is evaluated hierarchically over an AABB tree: exact solid angles
 * (van Oosterom-Strackee) near the point, a second-order multipole expansion
 * of far clusters. The distance is the exact point-triangle distance found
 * with the same tree.
 *
 * Faces may be given in either orientation as long as it is consistent:
 * the loader flips all faces when the signed volume comes out negative. */
#ifndef MPM_MESH_H
#define MPM_MESH_H

typedef struct Mesh Mesh;

/* Loads a closed mesh. 'v' and 'f' lines are read (faces with 3 or more
 * vertices are fan-triangulated; indices i, i/t, i/t/n, i//n, negative
 * relative indices); vt, vn, o, g, s, usemtl, mtllib, l, p and comments are
 * ignored. Fails with MPM_EINPUT and a message naming the file (and line)
 * for a missing file, a malformed line, a vertex coordinate that is not
 * finite or above 1e12 in magnitude (the value is quoted), an index out of range, a face with
 * fewer than 3 vertices, no faces, no enclosed volume, or a surface that is
 * not closed: boundary edges (edges used by an odd number of faces, e.g. by
 * exactly one) or edges between inconsistently oriented faces. Vertices at
 * identical positions count as one; edges shared by four faces, two in each
 * direction (two parts touching along an edge) are accepted. */
int mesh_load_obj(const char *path, Mesh **out);

/* The same, but accepts up to `max_boundary_edges` bad edges (boundary plus
 * inconsistently oriented) for nearly closed meshes; inside then means
 * "winding number >= 1/2", which degrades gracefully around small holes. */
int mesh_load_obj_lenient(const char *path, int max_boundary_edges, Mesh **out);

void mesh_free(Mesh *m);

/* Signed distance to the surface: negative inside, magnitude = exact
 * Euclidean distance to the nearest triangle. */
double mesh_signed_distance(const Mesh *m, const double x[3]);

/* Axis-aligned bounds of the vertices used by faces. */
void mesh_bounds(const Mesh *m, double lo[3], double hi[3]);

/* Enclosed volume (divergence theorem), positive. */
double mesh_volume(const Mesh *m);

/* Inside test only (cheaper than mesh_signed_distance): 1 inside, 0 outside. */
int mesh_contains(const Mesh *m, const double x[3]);

/* Generalized winding number at x (about 1 inside, 0 outside). */
double mesh_winding_number(const Mesh *m, const double x[3]);

/* All vertices of the file in file order (3 doubles each), e.g. for adding
 * them as particles the way HOT does; the triangle count; the number of bad
 * (boundary or inconsistently oriented) edges found at load. */
int mesh_vertex_count(const Mesh *m);
const double *mesh_vertices(const Mesh *m);
int mesh_triangle_count(const Mesh *m);
int mesh_boundary_edge_count(const Mesh *m);

#endif
