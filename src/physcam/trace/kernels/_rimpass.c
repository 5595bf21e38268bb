/* The Blender extension's rim pass in C: the rim points of the pupil tables' traced aim grids.

   Built into the _ckernel extension beside the tracing kernel (setup.py: the same flags, IEEE arithmetic without
   contraction or fast-math), and the same points, in the same order and by the same IEEE operations, as the numpy
   pass (physcam.export.blender_pupil_sets._rims, the reference; its notes have the geometry) and the numba port
   (kernels/_rimpass.py, whose loops these are, one for one). Per grid, toward +x, -x and +y, every pair of
   neighbouring samples where one passes at an iris radius and the other does not gives a rim point at that
   radius (the stop radius interpolated to it, or the halved clip edge), and every passing sample on the grid's
   edge a point a step out. Two calls: rim_counts finds each rim's rows (the pairs' radius ranges, summed), the
   caller allocates the points, rim_write writes each point in its rim's next row: no sort, no gathers.

   Arrays come through the buffer protocol (no numpy headers), C-contiguous, of the numba port's types (int64,
   float64, bool); the GIL is released while the loops run. An index the inputs would take out of bounds (a
   clip edge not in the table, a rim number past the rims) is an error, not a read or write past an array. */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* toward +x, -x, +y (blender_pupil_sets._TOWARD): the view's rows and columns less, the sample's (a) and the
   neighbour's (b) offsets in the grid (row, column), the step's direction (x, y) */
static const int DIRS[3][8] = {{0, 1, 0, 0, 0, 1, 1, 0}, {0, 1, 0, 1, 0, 0, -1, 0}, {1, 0, 0, 0, 1, 0, 0, 1}};

typedef struct {
    const unsigned char *ok, *wanted;
    const double *rad, *x0, *y0, *dx, *dy, *radii, *e_lo, *e_hi, *e_rad;
    const int64_t *n_in, *r0, *r1, *first_r0, *e_key;
    Py_ssize_t n_grid, ny, nx, n_rad, n_e, n_rims, n_out;
    int64_t *cuts;
    double *out;
} Rims;

/* ---- the loops (no Python calls: run without the GIL) ------------------------------------------------------ */

/* the first index of the ascending a[0:n] whose value is at least v (np.searchsorted's left side) */
static Py_ssize_t first_at_least(const int64_t *a, Py_ssize_t n, int64_t v)
{
    Py_ssize_t lo = 0, hi = n;
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) >> 1;
        if (a[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* grid g's sample (j, i) */
#define AT(g, j, i) (((g) * r->ny + (j)) * r->nx + (i))

/* span[lo] += 1, span[hi] -= 1 over every pair and edge sample of grid g with a point at some radius of its
   range (_rimpass._spans): a rim's points are the running sum at its radius */
static void spans(const Rims *r, Py_ssize_t g, int64_t *span)
{
    Py_ssize_t ny = r->ny, nx = r->nx;
    int64_t r0 = r->r0[g], r1 = r->r1[g];
    for (int d = 0; d < 3; d++) {
        const int *D = DIRS[d];
        for (Py_ssize_t jj = 0; jj < ny - D[0]; jj++)
            for (Py_ssize_t ii = 0; ii < nx - D[1]; ii++) {
                int64_t nb = r->n_in[AT(g, jj + D[4], ii + D[5])], na = r->n_in[AT(g, jj + D[2], ii + D[3])];
                int64_t lo = nb > r0 ? nb : r0, hi = na < r1 ? na : r1;
                if (hi > lo) {
                    span[lo] += 1;
                    span[hi] -= 1;
                }
            }
    }
    for (int e = 0; e < 3; e++)
        for (Py_ssize_t c = 0; c < (e < 2 ? ny : nx); c++) {
            Py_ssize_t jj = e < 2 ? c : ny - 1, ii = e == 0 ? 0 : (e == 1 ? nx - 1 : c);
            int64_t na = r->n_in[AT(g, jj, ii)], hi = na < r1 ? na : r1;
            if (hi > r0) {
                span[r0] += 1;
                span[hi] -= 1;
            }
        }
}

/* cuts[0] = 0 and cuts[k + 1] = cuts[k] + rim k's points, the rims grid after grid, radius index r0 to r1 of
   each (_rimpass.rim_points' count and cumsum; a rim not wanted has none); -1 where the rims are not n_rims */
static int counts(const Rims *r, int64_t *span)
{
    Py_ssize_t k = 0;
    r->cuts[0] = 0;
    for (Py_ssize_t g = 0; g < r->n_grid; g++) {
        memset(span, 0, (size_t)(r->n_rad + 1) * sizeof(int64_t));
        spans(r, g, span);
        int64_t running = 0;
        for (Py_ssize_t i = 0; i < r->n_rad; i++) {
            running += span[i];
            if (i < r->r0[g] || i >= r->r1[g])
                continue;
            if (k >= r->n_rims)
                return -1;
            r->cuts[k + 1] = r->cuts[k] + (r->wanted[g * r->n_rad + i] ? running : 0);
            k++;
        }
    }
    return k == r->n_rims ? 0 : -1;
}

/* rim point (x, y, xa, ya) to rim k's next row; -1 where k is not a rim or the row past its rim's or out's */
static int put(const Rims *r, int64_t *cur, int64_t k, double x, double y, double xa, double ya)
{
    if (k < 0 || k >= r->n_rims || cur[k] < 0 || cur[k] >= r->cuts[k + 1] || cur[k] >= r->n_out)
        return -1;
    double *o = r->out + 4 * cur[k]++;
    o[0] = x;
    o[1] = y;
    o[2] = xa;
    o[3] = ya;
    return 0;
}

/* the points of grid g's pairs toward direction d (_rimpass._write's first loop) */
static int pairs(const Rims *r, Py_ssize_t g, int d, int64_t *cur)
{
    const int *D = DIRS[d];
    int sx = D[6], sy = D[7];
    double step = sx * r->dx[g] + sy * r->dy[g];
    for (Py_ssize_t jj = 0; jj < r->ny - D[0]; jj++)
        for (Py_ssize_t ii = 0; ii < r->nx - D[1]; ii++) {
            Py_ssize_t ja = jj + D[2], ia = ii + D[3], jb = jj + D[4], ib = ii + D[5];
            int64_t nb = r->n_in[AT(g, jb, ib)], na = r->n_in[AT(g, ja, ia)];
            int64_t lo = nb > r->r0[g] ? nb : r->r0[g], hi = na < r->r1[g] ? na : r->r1[g];
            if (hi <= lo)
                continue;
            double ra = r->rad[AT(g, ja, ia)], r_e = INFINITY, e1 = 1.0, e_mid = 1.0, rate;
            if (r->ok[AT(g, jb, ib)]) {
                rate = 1.0 / (r->rad[AT(g, jb, ib)] - ra);
            } else {  /* the halved clip edge of this pair (blender_pupil_sets._clip_edges' key) */
                Py_ssize_t at = first_at_least(r->e_key, r->n_e, (int64_t)((g * 3 + d) * (r->ny * r->nx) + jj * r->nx + ii));
                if (at >= r->n_e)
                    return -2;
                r_e = r->e_rad[at];
                rate = r->e_lo[at] / (r->e_rad[at] - ra);
                e1 = r->e_hi[at];
                e_mid = 0.5 * (r->e_lo[at] + r->e_hi[at]);
            }
            double base, other;
            if (sx != 0) {
                base = r->x0[g] + (double)ia * r->dx[g];
                other = r->y0[g] + (double)ja * r->dy[g];
            } else {
                base = r->y0[g] + (double)ja * r->dy[g];
                other = r->x0[g] + (double)ia * r->dx[g];
            }
            for (int64_t i = lo; i < hi; i++) {
                if (!r->wanted[g * r->n_rad + i])
                    continue;
                double s = r->radii[i];
                double f = (s - ra) * rate;  /* clipped to [0, 1] as np.clip does (NaN and -0.0 kept) */
                if (f < 0.0)
                    f = 0.0;
                else if (f > 1.0)
                    f = 1.0;
                double fa = f;
                if (!(s < r_e)) {
                    f = e1;
                    fa = e_mid;
                }
                int64_t k = r->first_r0[g] + i;
                int bad = sx != 0 ? put(r, cur, k, base + step * f, other, base + step * fa, other)
                                  : put(r, cur, k, other, base + step * f, other, base + step * fa);
                if (bad)
                    return -1;
            }
        }
    return 0;
}

/* the points of grid g's edge samples, a step out past the grid's edge (_rimpass._write's second loop) */
static int edges(const Rims *r, Py_ssize_t g, int64_t *cur)
{
    for (int e = 0; e < 3; e++)  /* column 0, column nx - 1, row ny - 1 */
        for (Py_ssize_t c = 0; c < (e < 2 ? r->ny : r->nx); c++) {
            Py_ssize_t jj = e < 2 ? c : r->ny - 1, ii = e == 0 ? 0 : (e == 1 ? r->nx - 1 : c);
            int64_t na = r->n_in[AT(g, jj, ii)], lo = r->r0[g], hi = na < r->r1[g] ? na : r->r1[g];
            if (hi <= lo)
                continue;
            double bx = r->x0[g] + (double)ii * r->dx[g], by = r->y0[g] + (double)jj * r->dy[g];
            double ex = e == 0 ? -1 * r->dx[g] : (e == 1 ? 1 * r->dx[g] : 0.0);
            double ey = e == 2 ? 1 * r->dy[g] : 0.0;
            for (int64_t i = lo; i < hi; i++) {
                if (r->wanted[g * r->n_rad + i] && put(r, cur, r->first_r0[g] + i, bx + ex, by + ey, bx + ex / 2, by + ey / 2))
                    return -1;
            }
        }
    return 0;
}

static int write_all(const Rims *r, int64_t *cur)
{
    for (Py_ssize_t g = 0; g < r->n_grid; g++) {
        for (int d = 0; d < 3; d++) {
            int bad = pairs(r, g, d, cur);
            if (bad)
                return bad;
        }
        if (edges(r, g, cur))
            return -1;
    }
    return 0;
}

/* ---- Python entry --------------------------------------------------------------------------------------------- */

/* o's buffer, C-contiguous, of kind 'd' (float64), 'q' (int64) or '?' (bool), ndim dimensions of the shape
   (a -1 takes any length and is set to it) */
static int get(PyObject *o, Py_buffer *b, char kind, int ndim, Py_ssize_t *shape, int writable, const char *name)
{
    if (PyObject_GetBuffer(o, b, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    const char *f = b->format ? b->format : "B";
    while (*f == '@' || *f == '=' || (*f == '<' && PY_LITTLE_ENDIAN))
        f++;
    int type_ok = f[0] && f[1] == 0
                  && ((kind == 'd' && f[0] == 'd' && b->itemsize == 8) || (kind == '?' && f[0] == '?' && b->itemsize == 1)
                      || (kind == 'q' && (f[0] == 'q' || f[0] == 'l') && b->itemsize == 8));
    int shape_ok = b->ndim == ndim;
    for (int i = 0; shape_ok && i < ndim; i++) {
        if (shape[i] < 0)
            shape[i] = b->shape[i];
        shape_ok = b->shape[i] == shape[i];
    }
    if (!type_ok || !shape_ok) {
        PyErr_Format(PyExc_ValueError, "%s: a C-ordered %s array of %d dimensions of the grids' sizes", name,
                     kind == 'd' ? "float64" : (kind == 'q' ? "int64" : "bool"), ndim);
        PyBuffer_Release(b);
        return -1;
    }
    return 0;
}

/* the arguments both calls share: (ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo,
   e_hi, e_rad, cuts) into r and the 17 buffers b (released on error); 0, or -1 with the error set */
static int parse(PyObject *const *o, Rims *r, Py_buffer *b)
{
    Py_ssize_t G[3] = {-1, -1, -1}, W[2] = {-1, -1}, E[1] = {-1}, C[1] = {-1};
    int k = 0;
#define GET(kind, ndim, shape, w, name) \
    if (get(o[k], &b[k], kind, ndim, shape, w, name) < 0) \
        goto fail; \
    k++
    GET('?', 3, G, 0, "ok");
    GET('d', 3, G, 0, "rad");
    GET('q', 3, G, 0, "n_in");
    GET('d', 1, G, 0, "x0");
    GET('d', 1, G, 0, "y0");
    GET('d', 1, G, 0, "dx");
    GET('d', 1, G, 0, "dy");
    GET('q', 1, G, 0, "r0");
    GET('q', 1, G, 0, "r1");
    GET('q', 1, G, 0, "first_r0");
    W[0] = G[0];
    GET('?', 2, W, 0, "wanted");
    GET('d', 1, W + 1, 0, "radii");
    GET('q', 1, E, 0, "e_key");
    GET('d', 1, E, 0, "e_lo");
    GET('d', 1, E, 0, "e_hi");
    GET('d', 1, E, 0, "e_rad");
    GET('q', 1, C, 1, "cuts");
#undef GET
    memset(r, 0, sizeof *r);
    r->ok = b[0].buf, r->rad = b[1].buf, r->n_in = b[2].buf, r->x0 = b[3].buf, r->y0 = b[4].buf, r->dx = b[5].buf;
    r->dy = b[6].buf, r->r0 = b[7].buf, r->r1 = b[8].buf, r->first_r0 = b[9].buf, r->wanted = b[10].buf;
    r->radii = b[11].buf, r->e_key = b[12].buf, r->e_lo = b[13].buf, r->e_hi = b[14].buf, r->e_rad = b[15].buf;
    r->cuts = b[16].buf;
    r->n_grid = G[0], r->ny = G[1], r->nx = G[2], r->n_rad = W[1], r->n_e = E[0], r->n_rims = C[0] - 1;
    if (r->n_rims < 0 || (r->n_grid && (r->ny < 1 || r->nx < 1))) {
        PyErr_SetString(PyExc_ValueError, "cuts: one more than the rims; the grids: at least one sample");
        goto fail;
    }
    for (Py_ssize_t g = 0; g < r->n_grid; g++) {  /* a radius index outside [0, n_rad]: out of the spans' bounds */
        if (r->r0[g] < 0 || r->r1[g] > r->n_rad || r->r0[g] > r->r1[g]) {
            PyErr_SetString(PyExc_ValueError, "r0, r1: each grid's radius indices within the radii, r0 <= r1");
            goto fail;
        }
    }
    return 0;
fail:
    for (int i = 0; i < k; i++)
        PyBuffer_Release(&b[i]);
    return -1;
}

static PyObject *done(Py_buffer *b, int n, PyObject *result)
{
    for (int i = 0; i < n; i++)
        PyBuffer_Release(&b[i]);
    return result;
}

const char physcam_rim_counts_doc[] =
    "rim_counts(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo, e_hi, e_rad, cuts)\n\n"
    "Each rim's rows of the rim points: cuts[k] to cuts[k + 1] for rim k (cuts: int64, one more than the rims,\n"
    "written), the rims grid after grid, radius index r0 to r1 of each (kernels._rimpass.rim_points' arguments,\n"
    "C-ordered int64, float64 and bool). Releases the GIL.";

PyObject *physcam_rim_counts(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Rims r;
    Py_buffer b[17];
    if (nargs != 17) {
        PyErr_SetString(PyExc_TypeError, "rim_counts takes 17 arrays");
        return NULL;
    }
    if (parse(args, &r, b) < 0)
        return NULL;
    int64_t *span = malloc((size_t)(r.n_rad + 1) * sizeof(int64_t));
    if (!span)
        return done(b, 17, PyErr_NoMemory());
    int bad;
    Py_BEGIN_ALLOW_THREADS
    bad = counts(&r, span);
    Py_END_ALLOW_THREADS
    free(span);
    if (bad) {
        PyErr_SetString(PyExc_ValueError, "cuts: one more than the rims of the grids' radius ranges (sum of r1 - r0)");
        return done(b, 17, NULL);
    }
    Py_INCREF(Py_None);
    return done(b, 17, Py_None);
}

const char physcam_rim_write_doc[] =
    "rim_write(ok, rad, n_in, x0, y0, dx, dy, r0, r1, first_r0, wanted, radii, e_key, e_lo, e_hi, e_rad, cuts, out)\n\n"
    "The rim points (x, y, xa, ya) into out ((cuts[-1], 4) float64, written), rim k's in rows cuts[k] to\n"
    "cuts[k + 1] (rim_counts' cuts) in the numpy pass's order. Releases the GIL.";

PyObject *physcam_rim_write(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Rims r;
    Py_buffer b[18];
    if (nargs != 18) {
        PyErr_SetString(PyExc_TypeError, "rim_write takes 18 arrays");
        return NULL;
    }
    if (parse(args, &r, b) < 0)
        return NULL;
    Py_ssize_t rows[2] = {-1, 4};
    if (get(args[17], &b[17], 'd', 2, rows, 1, "out") < 0)
        return done(b, 17, NULL);
    r.out = b[17].buf;
    r.n_out = rows[0];
    int64_t *cur = malloc((size_t)(r.n_rims ? r.n_rims : 1) * sizeof(int64_t));
    if (!cur)
        return done(b, 18, PyErr_NoMemory());
    memcpy(cur, r.cuts, (size_t)r.n_rims * sizeof(int64_t));
    int bad;
    Py_BEGIN_ALLOW_THREADS
    bad = write_all(&r, cur);
    Py_END_ALLOW_THREADS
    free(cur);
    if (bad == -2)
        PyErr_SetString(PyExc_IndexError, "e_key: a pair toward a clipped neighbour has no clip edge past the last key");
    else if (bad)
        PyErr_SetString(PyExc_ValueError, "a rim point past its rim's rows (cuts not rim_counts' of these grids)");
    return done(b, 18, bad ? NULL : (Py_INCREF(Py_None), Py_None));
}
