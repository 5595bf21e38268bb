/* The compiled C kernel: the JIT kernel's blocked passes (kernels/_numba.py) compiled ahead of time.

   Same signature, algorithm, order of operations and answers as the numpy reference (kernels/_numpy.py;
   the maths and sources in docs/ray-tracing.md) and the numba kernel: identical flags, positions and
   directions. A block of BLOCK rays is copied into a scratch array of columns; for each surface the passes
   of the numba kernel run over the block, every lane doing the same operations with a lost lane masked
   (a select keeps its last state), so that a vectorising compiler can use packed instructions. The passes
   are the numba kernel's, one C function each, in the same order with the same expressions.

   Built without fast-math and with -ffp-contract=off (setup.py): no fused multiply-add, no reassociation,
   so every result is the IEEE double (or single) of the same expression as the reference: the Fresnel
   weights too (the numba kernel contracts those; they then differ from it by a few ulps, as numba's do
   from numpy's). -fno-math-errno only lets sqrt be one instruction (it changes no result).

   Arrays come through the buffer protocol (PEP 3118): no numpy headers at build time. Rays and table are
   float64 or float32 ("d"/"f"); float32 rays are traced in single precision as the numba kernel traces them
   (its float32 typing: every constant in the rays' precision, wavelength arithmetic in the wider of the
   wavelength's and the rays' types). The GIL is released while tracing, so the Python side
   (physcam.trace.kernels._c) runs ranges of blocks on threads as it does the numba kernel's.

   The file includes itself twice (CK_TEMPLATE) to instantiate the passes for double and float. */

#ifndef CK_TEMPLATE

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#if defined(_MSC_VER) && !defined(__clang__)
#define restrict __restrict /* MSVC's C before C11 */
#endif

#define BLOCK 256
/* scratch columns, each BLOCK long (the numba kernel's; ACT, CONV reuse CI, CT and DS reuses UPD) */
enum { PX, PY, PZ, DX, DY, DZ, W, WD, CD, T, L2, U, N1, N2, ETA, GX, GY, GZ, CI, CT, UPD, NCOL };
#define ACT CI
#define CONV CT
#define DS UPD
/* packed table columns (kernels/_layout.py) */
enum { S_VZ, S_AX, S_AY, S_AZ, S_CV, S_CK, S_SEMI, S_RSC, S_UNIT, S_N1, S_N2, S_ETA, S_SB, S_SA };
#define S_NB 14
#define S_NA (S_NB + 9)
#define S_A4 (S_NA + 9)
#define N_COLS (S_A4 + 7)
enum { K_FLAT, K_STOP, K_QUADRIC, K_ASPHERE };
enum { RF_OK, RF_MISSED, RF_CLIPPED, RF_TIR };
#define NEWTON_TOL 1e-12
#define NEWTON_MAX_ITER 40
#define NEWTON_TOL_F32 1e-6f

/* one call's arrays: ray columns by byte stride (any 1-D layout, as numba takes), the table as a
   contiguous copy in the rays' precision, kinds as int */
typedef struct {
    char *col[8];          /* x y z L M N w wd */
    Py_ssize_t st[8];
    const char *wl;
    Py_ssize_t wl_st;
    int wl_f64;
    unsigned char *flag;
    Py_ssize_t flag_st;
    double *opl;           /* NULL: no optical path */
    Py_ssize_t opl_st;
    const void *S;         /* ns x N_COLS, the rays' type */
    const int *kinds;
    int ns, clip, fresnel, has_end, mono;
    double end_z;
    Py_ssize_t n;
} Job;

#define CK_CAT2(a, b) a##b
#define CK_CAT(a, b) CK_CAT2(a, b)

/* The passes for each instruction set: the baseline of the platform, and on x86-64 with GCC also AVX2 and
   AVX-512 (the same C under #pragma GCC target; the widest the CPU supports is chosen at import, isa()).
   Packed and scalar IEEE operations round alike and nothing is contracted or reassociated, so every level
   gives the same rays (tests/trace/test_simd_kernel.py runs each level the machine has). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define CK_X86_LEVELS 1
#endif

#define CK_TEMPLATE 1
#define ISA _base
#include "_ckernel.c"
#undef ISA
#ifdef CK_X86_LEVELS
#pragma GCC push_options
#pragma GCC target("avx2")
#define ISA _avx2
#include "_ckernel.c"
#undef ISA
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512dq,avx512bw,prefer-vector-width=512")
#define ISA _avx512
#include "_ckernel.c"
#undef ISA
#pragma GCC pop_options
#endif
#undef CK_TEMPLATE

typedef void (*range_fn)(const Job *, Py_ssize_t, Py_ssize_t, void *);
static const char *isa_names[] = {"baseline", "avx2", "avx512"};
static range_fn ranges_d[] = {
    trace_range_d_base,
#ifdef CK_X86_LEVELS
    trace_range_d_avx2, trace_range_d_avx512,
#endif
};
static range_fn ranges_f[] = {
    trace_range_f_base,
#ifdef CK_X86_LEVELS
    trace_range_f_avx2, trace_range_f_avx512,
#endif
};
static int isa_level = 0;

/* the widest level this CPU (and its operating system's saved state) supports */
static int best_level(void)
{
#ifdef CK_X86_LEVELS
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq")
        && __builtin_cpu_supports("avx512bw"))
        return 2;
    if (__builtin_cpu_supports("avx2"))
        return 1;
#endif
    return 0;
}

/* ---- Python entry ------------------------------------------------------------------------------- */

static const char *skip_order(const char *f)
{
    /* native or little-endian standard sizes on a little-endian host: the same layout */
    while (*f == '@' || *f == '=' || (*f == '<' && PY_LITTLE_ENDIAN))
        f++;
    return f;
}

static char float_kind(const Py_buffer *v)
{
    const char *f = skip_order(v->format ? v->format : "B");
    if (f[0] == 'd' && f[1] == 0 && v->itemsize == 8)
        return 'd';
    if (f[0] == 'f' && f[1] == 0 && v->itemsize == 4)
        return 'f';
    return 0;
}

static int get_vec(PyObject *o, Py_buffer *v, int writable, const char *name, Py_ssize_t n)
{
    if (PyObject_GetBuffer(o, v, PyBUF_STRIDES | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (v->ndim != 1 || (n >= 0 && v->shape[0] != n)) {
        PyErr_Format(PyExc_ValueError, "%s: a 1-D array of the rays' length", name);
        PyBuffer_Release(v);
        return -1;
    }
    return 0;
}

static void release(Py_buffer *b, int k)
{
    for (int i = 0; i < k; i++)
        PyBuffer_Release(&b[i]);
}

/* the table's rows as a contiguous array in the rays' precision (its dtype must be theirs: the numba kernel
   would mix precisions, which this kernel does not reproduce), kinds as int */
static int load_table(Py_buffer *Sv, Py_buffer *Kv, char rk, void **S, int **kinds, int *ns)
{
    if (Sv->ndim != 2 || Sv->shape[1] != N_COLS || float_kind(Sv) != rk) {
        PyErr_Format(PyExc_TypeError, "the table must be (rows, %d) in the rays' precision", N_COLS);
        return -1;
    }
    const char *kf = skip_order(Kv->format ? Kv->format : "B");
    if (Kv->ndim != 1 || Kv->shape[0] != Sv->shape[0] || kf[1] != 0 || !strchr("bBhHiIlLqQ", kf[0])) {
        PyErr_SetString(PyExc_TypeError, "kinds: one integer per table row");
        return -1;
    }
    Py_ssize_t r = Sv->shape[0], isz = Sv->itemsize;
    *ns = (int)r;
    *S = malloc((size_t)(r ? r : 1) * N_COLS * isz);
    *kinds = malloc((size_t)(r ? r : 1) * sizeof(int));
    if (!*S || !*kinds) {
        free(*S);
        free(*kinds);
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t s = 0; s < r; s++) {
        for (Py_ssize_t c = 0; c < N_COLS; c++)
            memcpy((char *)*S + (s * N_COLS + c) * isz, (const char *)Sv->buf + s * Sv->strides[0] + c * Sv->strides[1],
                   isz);
        const char *p = (const char *)Kv->buf + s * Kv->strides[0];
        long long k;
        switch (Kv->itemsize) {
        case 1: k = (kf[0] == 'b') ? *(const signed char *)p : *(const unsigned char *)p; break;
        case 2: k = *(const short *)p; break;
        case 4: k = *(const int *)p; break;
        default: k = *(const long long *)p; break;
        }
        (*kinds)[s] = (int)k;
    }
    return 0;
}

PyDoc_STRVAR(trace_blocks_doc,
"trace_blocks(x, y, z, L, M, N, wl, w, wd, flag, S, kinds, clip, fresnel, end_z, has_end, mono, opl, b0, b1)\n\n"
"Trace blocks b0 .. b1 of BLOCK rays in place (the numpy kernel's trace_rays on those rays; opl: None or an\n"
"empty array for no optical path, else float64 per ray). Releases the GIL while tracing.");

static PyObject *trace_blocks(PyObject *self, PyObject *args)
{
    PyObject *o[12], *oopl;
    int clip, fresnel, has_end, mono;
    double end_z;
    Py_ssize_t b0, b1;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOppdppOnn", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &o[7],
                          &o[8], &o[9], &o[10], &o[11], &clip, &fresnel, &end_z, &has_end, &mono, &oopl, &b0, &b1))
        return NULL;
    static const char *names[] = {"x", "y", "z", "L", "M", "N", "wl", "w", "wd", "flag", "S", "kinds", "opl"};
    Py_buffer b[13];
    int k = 0;
    Py_ssize_t n = -1;
    /* x y z L M N w wd: writable, one float type */
    static const int ray_cols[8] = {0, 1, 2, 3, 4, 5, 7, 8};
    for (int i = 0; i < 10; i++) {
        int w = (i != 6);
        if (get_vec(o[i], &b[k], w, names[i], n) < 0) {
            release(b, k);
            return NULL;
        }
        n = b[k].shape[0];
        k++;
    }
    char rk = float_kind(&b[0]);
    for (int c = 0; c < 8; c++) {
        if (!rk || float_kind(&b[ray_cols[c]]) != rk) {
            PyErr_SetString(PyExc_TypeError, "rays: x y z L M N weight weight_sp all float64 or all float32");
            release(b, k);
            return NULL;
        }
    }
    char wk = float_kind(&b[6]);
    const char *ff = skip_order(b[9].format ? b[9].format : "B");
    if (!wk || ff[0] != 'B' || ff[1] != 0) {
        PyErr_SetString(PyExc_TypeError, "wavelength float64 or float32, flag uint8");
        release(b, k);
        return NULL;
    }
    if (PyObject_GetBuffer(o[10], &b[k], PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
        release(b, k);
        return NULL;
    }
    k++;
    if (PyObject_GetBuffer(o[11], &b[k], PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
        release(b, k);
        return NULL;
    }
    k++;
    int with_opl = 0;
    if (oopl != Py_None) {
        if (PyObject_GetBuffer(oopl, &b[k], PyBUF_STRIDES | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
            release(b, k);
            return NULL;
        }
        k++;
        if (b[12].ndim != 1 || float_kind(&b[12]) != 'd' || (b[12].shape[0] != 0 && b[12].shape[0] != n)) {
            PyErr_SetString(PyExc_TypeError, "opl: float64, one per ray (or empty: no optical path)");
            release(b, k);
            return NULL;
        }
        with_opl = b[12].shape[0] > 0;
    }
    Job j;
    memset(&j, 0, sizeof j);
    void *S = NULL;
    int *kinds = NULL;
    if (load_table(&b[10], &b[11], rk, &S, &kinds, &j.ns) < 0) {
        release(b, k);
        return NULL;
    }
    for (int c = 0; c < 8; c++) {
        j.col[c] = b[ray_cols[c]].buf;
        j.st[c] = b[ray_cols[c]].strides[0];
    }
    j.wl = b[6].buf;
    j.wl_st = b[6].strides[0];
    j.wl_f64 = wk == 'd';
    j.flag = b[9].buf;
    j.flag_st = b[9].strides[0];
    j.opl = with_opl ? (double *)b[12].buf : NULL;
    j.opl_st = with_opl ? b[12].strides[0] : 0;
    j.S = S;
    j.kinds = kinds;
    j.clip = clip;
    j.fresnel = fresnel;
    j.has_end = has_end;
    j.mono = mono;
    j.end_z = end_z;
    j.n = n;
    Py_ssize_t nb = (n + BLOCK - 1) / BLOCK;
    if (b0 < 0)
        b0 = 0;
    if (b1 > nb)
        b1 = nb;
    int ok = 1;
    if (b0 < b1) {
        void *buf = malloc(NCOL * BLOCK * (size_t)(rk == 'd' ? sizeof(double) : sizeof(float)));
        if (!buf) {
            ok = 0;
        } else {
            Py_BEGIN_ALLOW_THREADS
            (rk == 'd' ? ranges_d : ranges_f)[isa_level](&j, b0, b1, buf);
            Py_END_ALLOW_THREADS
            free(buf);
        }
    }
    free(S);
    free(kinds);
    release(b, k);
    if (!ok)
        return PyErr_NoMemory();
    Py_RETURN_NONE;
}

static PyObject *isa(PyObject *self, PyObject *noargs)
{
    return PyUnicode_FromString(isa_names[isa_level]);
}

static PyObject *isa_levels(PyObject *self, PyObject *noargs)
{
    PyObject *out = PyTuple_New(best_level() + 1);
    for (int i = 0; out && i <= best_level(); i++)
        PyTuple_SET_ITEM(out, i, PyUnicode_FromString(isa_names[i]));
    return out;
}

static PyObject *set_isa(PyObject *self, PyObject *arg)
{
    const char *name = PyUnicode_AsUTF8(arg);
    if (!name)
        return NULL;
    for (int i = 0; i <= best_level(); i++) {
        if (strcmp(name, isa_names[i]) == 0) {
            isa_level = i;
            Py_RETURN_NONE;
        }
    }
    PyErr_Format(PyExc_ValueError, "instruction set %R is not one this build and CPU have (isa_levels())", arg);
    return NULL;
}

/* the Blender extension's rim pass (_rimpass.c, built into this module) */
extern const char physcam_rim_counts_doc[], physcam_rim_write_doc[];
PyObject *physcam_rim_counts(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *physcam_rim_write(PyObject *self, PyObject *const *args, Py_ssize_t nargs);

static PyMethodDef methods[] = {
    {"trace_blocks", trace_blocks, METH_VARARGS, trace_blocks_doc},
    {"rim_counts", (PyCFunction)(void (*)(void))physcam_rim_counts, METH_FASTCALL, physcam_rim_counts_doc},
    {"rim_write", (PyCFunction)(void (*)(void))physcam_rim_write, METH_FASTCALL, physcam_rim_write_doc},
    {"isa", isa, METH_NOARGS, "The instruction set the kernel runs with (the widest this CPU has, or set_isa's)."},
    {"isa_levels", isa_levels, METH_NOARGS, "The instruction sets this build has and this CPU runs."},
    {"set_isa", set_isa, METH_O, "Run with one of isa_levels() (tests: every level gives the same rays)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ckernel",
    "The compiled C tracing kernel (physcam.trace.kernels._ckernel.c; docs/ray-tracing.md).", -1, methods,
};

PyMODINIT_FUNC PyInit__ckernel(void)
{
    isa_level = best_level();
    PyObject *m = PyModule_Create(&module);
    if (m && PyModule_AddIntConstant(m, "BLOCK", BLOCK) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}

#elif CK_TEMPLATE == 1 /* one instruction set (ISA): the passes in double and in float */

#undef CK_TEMPLATE
#define CK_TEMPLATE 2
#define R double
#define SUF CK_CAT(_d, ISA)
#define SQRT sqrt
#define FABS fabs
#define IS_F32 0
#include "_ckernel.c"
#undef R
#undef SUF
#undef SQRT
#undef FABS
#undef IS_F32
#define R float
#define SUF CK_CAT(_f, ISA)
#define SQRT sqrtf
#define FABS fabsf
#define IS_F32 1
#include "_ckernel.c"
#undef R
#undef SUF
#undef SQRT
#undef FABS
#undef IS_F32
#undef CK_TEMPLATE
#define CK_TEMPLATE 1

#else /* CK_TEMPLATE 2: the passes in precision R (double or float) for one instruction set */

#define FN(name) CK_CAT(name, SUF)
/* a block holds at most BLOCK lanes: told to the compiler, it knows the columns' lanes never overlap and
   vectorises the passes without a run-time overlap check (GCC left them scalar under AVX2 otherwise) */
#if defined(__GNUC__)
#define LANES(m) if ((m) > BLOCK) __builtin_unreachable()
#else
#define LANES(m) (void)0
#endif
#define COL(c) (buf + (c) * BLOCK)
#define RAYV(j, c, i) (*(R *)((j)->col[c] + (i) * (j)->st[c]))
#define SV(S, s, c) ((S)[(s) * N_COLS + (c)])

/* t to the plane z = vz into column T; a live ray parallel to it misses */
static void FN(intersect_plane)(R *restrict buf, int m, R vz)
{
    LANES(m);
    const R zero = 0, miss = RF_MISSED;
    for (int k = 0; k < m; k++) {
        R dz = COL(DZ)[k], cd = COL(CD)[k];
        COL(T)[k] = -(COL(PZ)[k] - vz) / dz;
        COL(CD)[k] = ((cd == zero) & (dz == zero)) ? miss : cd;
    }
}

/* the forward-crossing root of ax x^2 + ay y^2 + az z^2 - 2 z = 0 (numba kernel, _intersect_quadric) */
static void FN(intersect_quadric)(R *restrict buf, int m, R vz, R ax, R ay, R az)
{
    LANES(m);
    const R zero = 0, one = 1, two = 2, miss = RF_MISSED;
    for (int k = 0; k < m; k++) {
        R px = COL(PX)[k], py = COL(PY)[k], qz = COL(PZ)[k] - vz;
        R dx = COL(DX)[k], dy = COL(DY)[k], dz = COL(DZ)[k], cd = COL(CD)[k];
        R a = ax * dx * dx + ay * dy * dy + az * dz * dz;
        R b = ax * px * dx + ay * py * dy + az * qz * dz - dz;
        R c = ax * px * px + ay * py * py + az * qz * qz - two * qz;
        R disc = b * b - a * c;
        R sq = SQRT(zero > disc ? zero : disc); /* numba's max(disc, 0): NaN stays NaN */
        R sgn = dz >= zero ? one : -one;
        int same = b * sgn >= zero;
        R num = same ? -b - sgn * sq : c;
        R den = same ? a : -b + sgn * sq;
        R t = num / den;
        int bad = (disc < zero) | (den == zero) | !(az * (qz + t * dz) < one);
        COL(T)[k] = t;
        COL(CD)[k] = ((cd == zero) & bad) ? miss : cd;
    }
}

/* sum of the even terms and of their derivative (the numba kernel's term-by-term order) */
#define ASPH_TERMS(sag, dsr, p, q, r2)                                                                  \
    do {                                                                                                \
        for (int i_ = 0; i_ < 7; i_++) {                                                                \
            sag = sag + a[i_] * p;                                                                      \
            dsr = dsr + c[i_] * q;                                                                      \
            p = p * r2;                                                                                 \
            q = q * r2;                                                                                 \
        }                                                                                               \
    } while (0)

/* Newton on g(t) = z(t) - sag(r(t)) from the conic root (numba kernel, _newton_asphere): every live lane
   steps until it converges or breaks, at most NEWTON_MAX_ITER steps; then dz/dr per unit r into DS and the
   lanes that did not converge MISSED */
static void FN(newton_asphere)(R *restrict buf, int m, const R *S, int s, R vz)
{
    LANES(m);
    const R zero = 0, one = 1, miss = RF_MISSED;
#if IS_F32
    const R rel = (R)(8.0 * 1.1920928955078125e-07), tol = NEWTON_TOL_F32;
#else
    const R rel = 0.0, tol = NEWTON_TOL;
#endif
    R cv = SV(S, s, S_CV);
    R ck1 = (one + SV(S, s, S_CK)) * cv * cv;
    R a[7], c[7];
    for (int i = 0; i < 7; i++) {
        a[i] = SV(S, s, S_A4 + i);
        c[i] = (R)(2 * i + 4) * a[i];
    }
    int nact = 0;
    for (int k = 0; k < m; k++) {
        int live = COL(CD)[k] == zero;
        COL(ACT)[k] = live ? one : zero;
        COL(CONV)[k] = zero;
        nact += live;
    }
    for (int it = 0; it < NEWTON_MAX_ITER && nact; it++) {
        nact = 0;
        for (int k = 0; k < m; k++) {
            int act = COL(ACT)[k] != zero;
            R dx = COL(DX)[k], dy = COL(DY)[k], dz = COL(DZ)[k], t = COL(T)[k];
            R X = COL(PX)[k] + t * dx, Y = COL(PY)[k] + t * dy, Z = (COL(PZ)[k] - vz) + t * dz;
            R r2 = X * X + Y * Y;
            R arg = one - ck1 * r2;
            R sa = SQRT(arg);
            R sag = cv * r2 / (one + sa);
            R dsr = cv / sa;
            R p = r2 * r2, q = r2;
            ASPH_TERMS(sag, dsr, p, q, r2);
            R g = Z - sag;
            R gp = dz - dsr * (X * dx + Y * dy);
            int broken = (arg < zero) | (gp == zero);
            int step = act & !broken;
            R dt = g / gp;
            dt = step ? dt : zero;
            int conv = step & (FABS(dt) < tol + rel * FABS(t));
            COL(T)[k] = t - dt;
            int still = step & !conv;
            COL(ACT)[k] = still ? one : zero;
            COL(CONV)[k] = conv ? one : COL(CONV)[k];
            nact += still;
        }
    }
    for (int k = 0; k < m; k++) {
        R t = COL(T)[k];
        R X = COL(PX)[k] + t * COL(DX)[k], Y = COL(PY)[k] + t * COL(DY)[k];
        R r2 = X * X + Y * Y;
        R arg = one - ck1 * r2;
        R dsr = cv / SQRT(arg);
        R q = r2;
        for (int i = 0; i < 7; i++) {
            dsr = dsr + c[i] * q;
            q = q * r2;
        }
        COL(DS)[k] = dsr;
        R cd = COL(CD)[k];
        int bad = (cd == zero) & ((COL(CONV)[k] == zero) | (arg < zero));
        COL(CD)[k] = bad ? miss : cd;
    }
}

/* live lanes to their hit point; clipped outside the semi-diameter; a hit point that is not finite MISSED */
static void FN(move_and_clip)(R *restrict buf, int m, R sd2, int clip)
{
    LANES(m);
    const R zero = 0, miss = RF_MISSED, clipped = RF_CLIPPED;
    for (int k = 0; k < m; k++) {
        R cd = COL(CD)[k], t = COL(T)[k];
        int live = cd == zero;
        R px = COL(PX)[k], py = COL(PY)[k], pz = COL(PZ)[k];
        R hx = px + t * COL(DX)[k], hy = py + t * COL(DY)[k], hz = pz + t * COL(DZ)[k];
        R r2 = hx * hx + hy * hy;
        int finite = r2 - r2 == zero;
        int ok = live & finite & ((r2 <= sd2) | !clip);
        COL(PX)[k] = ok ? hx : px;
        COL(PY)[k] = ok ? hy : py;
        COL(PZ)[k] = ok ? hz : pz;
        COL(CD)[k] = (ok | !live) ? cd : (finite ? clipped : miss);
    }
}

/* surface normals, pointing to -z at the vertex */
static void FN(normal)(R *restrict buf, int m, int kd, R vz, R ax, R ay, R az)
{
    LANES(m);
    const R zero = 0, one = 1;
    for (int k = 0; k < m; k++) {
        if (kd == K_FLAT) {
            COL(GX)[k] = zero;
            COL(GY)[k] = zero;
            COL(GZ)[k] = -one;
        } else if (kd == K_QUADRIC) {
            COL(GX)[k] = ax * COL(PX)[k];
            COL(GY)[k] = ay * COL(PY)[k];
            COL(GZ)[k] = az * (COL(PZ)[k] - vz) - one;
        } else {
            R ds = COL(DS)[k];
            COL(GX)[k] = ds * COL(PX)[k];
            COL(GY)[k] = ds * COL(PY)[k];
            COL(GZ)[k] = -one;
        }
    }
}

static void FN(normalise)(R *restrict buf, int m)
{
    LANES(m);
    const R one = 1;
    for (int k = 0; k < m; k++) {
        R gx = COL(GX)[k], gy = COL(GY)[k], gz = COL(GZ)[k];
        R inv = one / SQRT(gx * gx + gy * gy + gz * gz);
        COL(GX)[k] = gx * inv;
        COL(GY)[k] = gy * inv;
        COL(GZ)[k] = gz * inv;
    }
}

/* index of one medium per lane (physcam.optics.glass.evaluate's arithmetic and order) into column col */
static void FN(fill_index)(R *restrict buf, int col, const R *S, int s, int c, int flag, int m)
{
    LANES(m);
    const R one = 1;
    R a0 = SV(S, s, c), a1 = SV(S, s, c + 1), a2 = SV(S, s, c + 2);
    if (SV(S, s, flag) != 0) {
        R b1 = SV(S, s, c + 3), b2 = SV(S, s, c + 4), b3 = SV(S, s, c + 5);
        R c1 = SV(S, s, c + 6), c2 = SV(S, s, c + 7), c3 = SV(S, s, c + 8);
        for (int k = 0; k < m; k++) {
            R u = COL(U)[k], l2 = COL(L2)[k];
            COL(col)[k] = (a0 + (a1 + a2 * u) * u) + SQRT(one + b1 * l2 / (l2 - c1) + b2 * l2 / (l2 - c2)
                                                          + b3 * l2 / (l2 - c3));
        }
    } else {
        for (int k = 0; k < m; k++) {
            R u = COL(U)[k];
            COL(col)[k] = a0 + (a1 + a2 * u) * u;
        }
    }
}

/* Snell's law in vector form with the normal turned to the side the ray travels to; TIR, or MISSED on a
   NaN (a degenerate normal); leaves cos i, cos t and whether the lane refracted for the Fresnel pass */
static void FN(refract)(R *restrict buf, int m)
{
    LANES(m);
    const R zero = 0, one = 1, miss = RF_MISSED, tir_code = RF_TIR;
    for (int k = 0; k < m; k++) {
        R cd = COL(CD)[k];
        int live = cd == zero;
        R dx = COL(DX)[k], dy = COL(DY)[k], dz = COL(DZ)[k];
        R gx = COL(GX)[k], gy = COL(GY)[k], gz = COL(GZ)[k];
        R eta = COL(ETA)[k];
        int same = COL(N1)[k] == COL(N2)[k];
        R ci = dx * gx + dy * gy + dz * gz;
        int flip = ci < zero;
        gx = flip ? -gx : gx;
        gy = flip ? -gy : gy;
        gz = flip ? -gz : gz;
        ci = flip ? -ci : ci;
        R kk = one - eta * eta * (one - ci * ci);
        int good = (kk >= zero) | same;
        int tir = live & !good & (kk < zero) & (ci - ci == zero);
        int upd = live & good & !same;
        R ct = SQRT(zero > kk ? zero : kk);
        R f = ct - eta * ci;
        COL(DX)[k] = upd ? eta * dx + f * gx : dx;
        COL(DY)[k] = upd ? eta * dy + f * gy : dy;
        COL(DZ)[k] = upd ? eta * dz + f * gz : dz;
        COL(CD)[k] = tir ? tir_code : ((live & !good) ? miss : cd);
        COL(CI)[k] = ci;
        COL(CT)[k] = ct;
        COL(UPD)[k] = upd ? one : zero;
    }
}

/* Fresnel s and p transmission on the weights of the lanes that refracted (the numpy kernel's order,
   not contracted); R clipped to 1 */
static void FN(fresnel_pass)(R *restrict buf, int m, R rsc)
{
    LANES(m);
    const R zero = 0, one = 1, half = 0.5;
    for (int k = 0; k < m; k++) {
        R eta = COL(ETA)[k], ci = COL(CI)[k], ct = COL(CT)[k];
        int upd = COL(UPD)[k] != zero;
        R ec = eta * ci, et = eta * ct;
        R sm = (ec - ct) * (ci + et);
        R pm = (ci - et) * (ec + ct);
        R sp = (ec + ct) * (ci + et);
        R qq = rsc / (sp * sp);
        R rs = sm * sm * qq;
        rs = rs < one ? rs : one;
        R rp = pm * pm * qq;
        rp = rp < one ? rp : one;
        R hsum = one - half * (rs + rp);
        R hdif = half * (rp - rs);
        R w0 = COL(W)[k], d0 = COL(WD)[k];
        COL(W)[k] = upd ? w0 * hsum + d0 * hdif : w0;
        COL(WD)[k] = upd ? w0 * hdif + d0 * hsum : d0;
    }
}

/* live lanes on to the plane z = end_z; parallel to it, or landing at inf/NaN: MISSED */
static void FN(to_plane)(R *restrict buf, int m, R end_z)
{
    LANES(m);
    const R zero = 0, miss = RF_MISSED;
    for (int k = 0; k < m; k++) {
        R cd = COL(CD)[k];
        int live = cd == zero;
        R px = COL(PX)[k], py = COL(PY)[k], pz = COL(PZ)[k], dz = COL(DZ)[k];
        R t = (end_z - pz) / dz;
        R hx = px + t * COL(DX)[k], hy = py + t * COL(DY)[k];
        int ok = live & (dz != zero) & (hx - hx == zero) & (hy - hy == zero);
        COL(PX)[k] = ok ? hx : px;
        COL(PY)[k] = ok ? hy : py;
        COL(PZ)[k] = ok ? end_z : pz;
        COL(CD)[k] = (live & !ok) ? miss : cd;
    }
}

/* each live lane's leg n t |d|^2 added to opl (n: the constant n1, or column N1 when n1c is NULL) */
static void FN(add_path)(R *restrict buf, int m, const R *n1c, R n1, const Job *j, Py_ssize_t i0)
{
    LANES(m);
    const R zero = 0;
    for (int k = 0; k < m; k++) {
        R dx = COL(DX)[k], dy = COL(DY)[k], dz = COL(DZ)[k];
        R n = n1c ? n1c[k] : n1;
        R leg = n * (COL(T)[k] * (dx * dx + dy * dy + dz * dz));
        int live = COL(CD)[k] == zero;
        double *o = (double *)((char *)j->opl + (i0 + k) * j->opl_st);
        *o += live ? (double)leg : 0.0;
    }
}

/* copy a block in; flag live rays without finite weights or (each ray's own wavelength) a usable one:
   the wavelength arithmetic in the wider of the wavelength's and the rays' types, as numba types it */
static void FN(load_block)(R *restrict buf, const Job *j, Py_ssize_t i0, int m)
{
    const R zero = 0, miss = RF_MISSED;
    for (int k = 0; k < m; k++) {
        Py_ssize_t i = i0 + k;
        for (int c = 0; c < 6; c++)
            COL(c)[k] = RAYV(j, c, i);
        COL(W)[k] = RAYV(j, 6, i);
        COL(WD)[k] = RAYV(j, 7, i);
        COL(CD)[k] = (R)j->flag[i * j->flag_st];
    }
    for (int k = 0; k < m; k++) {
        Py_ssize_t i = i0 + k;
        R v = COL(W)[k] + COL(WD)[k];
        R cd = COL(CD)[k];
        int good = v - v == zero;
        if (!j->mono) {
            const char *p = j->wl + i * j->wl_st;
            if (j->wl_f64 || !IS_F32) {
                double wl = j->wl_f64 ? *(const double *)p : (double)*(const float *)p;
                double lam = wl / 1000.0, l2 = lam * lam, u = 1.0 / l2;
                COL(L2)[k] = (R)l2;
                COL(U)[k] = (R)u;
                good = good & (wl > 0.0) & (u - u == 0.0);
            } else {
                float wl = *(const float *)p;
                float lam = wl / 1000.0f, l2 = lam * lam, u = 1.0f / l2;
                COL(L2)[k] = (R)l2;
                COL(U)[k] = (R)u;
                good = good & (wl > 0.0f) & (u - u == 0.0f);
            }
        }
        COL(CD)[k] = ((cd == zero) & !good) ? miss : cd;
    }
}

/* copy a block out: a ray lost here gets weight 0 */
static void FN(store_block)(const R *restrict buf, const Job *j, Py_ssize_t i0, int m)
{
    const R zero = 0;
    for (int k = 0; k < m; k++) {
        Py_ssize_t i = i0 + k;
        R cd = COL(CD)[k];
        unsigned char *f = j->flag + i * j->flag_st;
        int lost = (cd != zero) & (*f == 0);
        for (int c = 0; c < 6; c++)
            RAYV(j, c, i) = COL(c)[k];
        RAYV(j, 6, i) = lost ? zero : COL(W)[k];
        RAYV(j, 7, i) = lost ? zero : COL(WD)[k];
        *f = (unsigned char)cd;
    }
}

/* one surface on a block: the numba kernel's passes in its order */
static void FN(surface)(R *restrict buf, const Job *j, int s, int m, Py_ssize_t i0)
{
    const R *S = (const R *)j->S;
    int kd = j->kinds[s];
    R vz = SV(S, s, S_VZ), ax = SV(S, s, S_AX), ay = SV(S, s, S_AY), az = SV(S, s, S_AZ);
    if (kd <= K_STOP) {
        FN(intersect_plane)(buf, m, vz);
    } else {
        FN(intersect_quadric)(buf, m, vz, ax, ay, az);
        if (kd == K_ASPHERE)
            FN(newton_asphere)(buf, m, S, s, vz);
    }
    FN(move_and_clip)(buf, m, SV(S, s, S_SEMI) * SV(S, s, S_SEMI), j->clip);
    int n1_filled = 0;
    if (j->opl) {
        if (j->mono) {
            FN(add_path)(buf, m, NULL, SV(S, s, S_N1), j, i0);
        } else {
            FN(fill_index)(buf, N1, S, s, S_NB, S_SB, m);
            n1_filled = 1;
            FN(add_path)(buf, m, COL(N1), 0, j, i0);
        }
    }
    if (kd == K_STOP)
        return;
    if (j->mono) {
        R n1 = SV(S, s, S_N1), n2 = SV(S, s, S_N2), eta = SV(S, s, S_ETA);
        if (n1 == n2)
            return;
        for (int k = 0; k < m; k++) {
            COL(N1)[k] = n1;
            COL(N2)[k] = n2;
            COL(ETA)[k] = eta;
        }
    } else {
        if (!n1_filled)
            FN(fill_index)(buf, N1, S, s, S_NB, S_SB, m);
        FN(fill_index)(buf, N2, S, s, S_NA, S_SA, m);
        for (int k = 0; k < m; k++)
            COL(ETA)[k] = COL(N1)[k] / COL(N2)[k];
    }
    FN(normal)(buf, m, kd, vz, ax, ay, az);
    if (SV(S, s, S_UNIT) == 0)
        FN(normalise)(buf, m);
    FN(refract)(buf, m);
    if (j->fresnel)
        FN(fresnel_pass)(buf, m, SV(S, s, S_RSC));
}

/* blocks b0 .. b1 through every surface (a block whose lanes all stopped leaves the surface loop), then to
   the end plane */
static void FN(trace_range)(const Job *j, Py_ssize_t b0, Py_ssize_t b1, void *scratch)
{
    R *buf = (R *)scratch;
    const R zero = 0;
    for (Py_ssize_t blk = b0; blk < b1; blk++) {
        Py_ssize_t i0 = blk * BLOCK;
        int m = (int)(j->n - i0 < BLOCK ? j->n - i0 : BLOCK);
        FN(load_block)(buf, j, i0, m);
        for (int s = 0; s < j->ns; s++) {
            int alive = 0;
            for (int k = 0; k < m; k++) {
                if (COL(CD)[k] == zero) {
                    alive = 1;
                    break;
                }
            }
            if (!alive)
                break;
            FN(surface)(buf, j, s, m, i0);
        }
        if (j->has_end)
            FN(to_plane)(buf, m, (R)j->end_z);
        FN(store_block)(buf, j, i0, m);
    }
}

#undef FN
#undef COL
#undef RAYV
#undef SV
#undef ASPH_TERMS

#endif /* CK_TEMPLATE */
