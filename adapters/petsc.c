/* PETSc KSP/PC behind the InvApprox interface (adapters/petsc.h; docs/solvers.md).
 *
 * API use follows the PETSc 3.18 manual pages (petsc.org/release/manualpages:
 * MatSeqBAIJSetPreallocationCSR, MatSeqBAIJGetArray, MatNullSpaceCreateRigidBody,
 * KSPSetOptionsPrefix, PetscOptionsUsed, PetscPushErrorHandler) and the comments
 * of the installed headers.
 *
 * Choices:
 *  - The matrix: MATSEQBAIJ, block size 3, the Hessian's own block pattern
 *    (row_ptr/col, columns sorted). Its structure is made once per pattern
 *    by MatSeqBAIJSetPreallocationCSR; the values are then written straight
 *    into PETSc's value array (MatSeqBAIJGetArray), block k of the Hessian
 *    into block k of PETSc's (the same sorted order), transposed because
 *    BAIJ keeps each block column-major. MatCreateSeqBAIJWithArrays would
 *    avoid the copy, but it reads blocks column-major too: the Hessian's
 *    row-major blocks would be the transposes, a different matrix off the
 *    diagonal, so the copy is needed (its cost against one SpMV:
 *    docs/solvers.md, measured by tests/conformance/test_adapters.c).
 *  - Options: PETSc's global options database under a prefix of this
 *    instance's own ("mpm<k>_"), set with KSPSetOptionsPrefix, so that the
 *    KSP, its PC and every sub-object (GAMG's levels: mpm<k>_mg_levels_...)
 *    read them and two solvers never see each other's. PetscOptionsUsed on
 *    each given key after a set-up on a built-in probe matrix (create) is
 *    the -options_left check, per instance.
 *  - Errors: an error handler that records PETSc's first message and
 *    returns the code, so nothing is printed and every failure becomes one
 *    mpm_error line.
 *  - Determinism: every full setup makes a new KSP (GAMG's eigenvalue
 *    estimates start from a new object's random state), so equal matrices
 *    give equal preconditioners. */
#include "adapters/petsc.h"

#include <mpi.h>
#include <petscksp.h>
/* PETSc's own (installed) internal header, for PetscObjectStateIncrease:
 * the values written into the Mat's array behind MatSetValues' back must
 * mark the Mat changed, as MatSetValues does, or PCSetUp would keep the
 * old preconditioner */
#include <petsc/private/petscimpl.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/mpi_startup.h"
#include "adapters/petsc_error.h"
#include "adapters/petsc_hierarchy.h"
#include "core/dist/node_numbering.h"
#include "core/error.h"
#include "solvers/mg/mg.h"

#if defined(PETSC_USE_64BIT_INDICES) || defined(PETSC_USE_COMPLEX) || !defined(PETSC_USE_REAL_DOUBLE)
#error "adapters/petsc.c expects PETSc with 32-bit PetscInt and real double scalars (Debian's libpetsc-real3.18-dev)"
#endif

enum { PETSC_MAX_KEYS = SOLVER_MAX_OPTS, PROBE_NODES_PER_AXIS = 8 };

typedef struct {
    InvApprox base;
    /* options */
    char prefix[24]; /* "mpm<k>_": this instance's PETSc options */
    int n_keys;      /* PETSc options set under the prefix (ksp_type and pc_type first) */
    char key[PETSC_MAX_KEYS][SOLVER_OPT_KEY];
    char value[PETSC_MAX_KEYS][64];
    int n_given;     /* of them, the ones the user gave (checked for use) */
    int given[PETSC_MAX_KEYS];
    int options_set; /* the keys are in PETSc's database */
    int complete;    /* ksp_type != preonly: apply is a KSPSolve */
    int rbm;
    int baij;
    /* petsc_hierarchy: HOT's embedding levels as a PCMG (adapters/petsc_hierarchy.h); NULL = none */
    PetscHierarchy *hier;
    const int *coord;                 /* the nodes of the last setup_on (referenced) */
    const NodeColoring *coloring;        /* petsc_mat_type=baij: MATSEQBAIJ; else MATSEQAIJ of block size 3 */
    /* the matrix; NULL = none */
    Mat A;
    int n;
    int64_t nnzb;
    uint64_t pattern_id;
    PetscInt *ia, *ja; /* A's pattern in PETSc's index type: block CSR (baij) or scalar CSR (aij) */
    int64_t cap_ia, cap_ja;
    /* the solver of the last successful setup; NULL = none */
    KSP ksp;
    Vec b, x; /* arrays placed at each apply */
    int ready;
    /* the Dirichlet projection of the last setup or reuse (NULL: none) and
     * the projected input of apply */
    const Projection *proj;
    double *r_proj;
    int64_t cap_r;
    /* Across ranks (docs/distributed.md): the last setup's split. The Mat
     * and vectors are PETSc's parallel ones over the owned nodes, numbered
     * by dist_node_numbering; rows come from every rank's part of the
     * Hessian (ghost rows too) through MatSetValuesBlocked with ADD_VALUES,
     * PETSc's assembly moving the off-rank blocks to their owners. */
    int dist;
    const unsigned char *owned;
    NodeNumbering num;
    int *gid; /* per local node: its global number */
    int cap_gid;
    PetscInt *row_cols; /* one block row's global columns */
    PetscScalar *row_vals; /* and its values, 3 x 3len row-major */
    int64_t cap_row;
    double *r_owned, *z_owned; /* the owned nodes' entries, packed */
    int64_t cap_owned;
    /* petsc_hierarchy across ranks: the owned nodes' coordinates, packed, and the split */
    int *owned_coord;
    const CommOps *comm;
    const Decomposition *decomp;
} Petsc;

/* ---- start-up, errors ---- */

static int g_petsc_ready = 0, g_next_prefix = 0;
/* PETSc's return code as an mpm status (adapters/petsc_error.h) */
static int pk(PetscErrorCode code, int status, const char *what) { return petsc_status(code, status, what); }

/* At exit: PETSc, before MPI's finaliser (registered earlier by
 * adapter_mpi_start). When the program finalised MPI itself (the matrix
 * runner under mpirun), PETSc cannot be finalised any more and is left as
 * it is. */
static void petsc_at_exit(void)
{
    if (!g_petsc_ready) return;
    if (adapter_mpi_running()) PetscFinalize();
    g_petsc_ready = 0;
}

int petsc_library_startup(void)
{
    if (g_petsc_ready) return MPM_OK;
    int st = adapter_mpi_start("petsc");
    if (st) return st;
    /* no signal handlers (the run's own stay), no ~/.petscrc, and no
     * unused-options report at PetscFinalize (the adapter checks its own) */
    static char arg0[] = "mpmbench", arg1[] = "-no_signal_handler", arg2[] = "-skip_petscrc", arg3[] = "-options_left",
                arg4[] = "no";
    static char *argv_store[] = {arg0, arg1, arg2, arg3, arg4, NULL};
    int argc = 5;
    char **argv = argv_store;
    if (PetscInitialize(&argc, &argv, NULL, NULL)) return mpm_error(MPM_EINTERNAL, "petsc: PetscInitialize failed");
    PetscPushErrorHandler(petsc_record_error, NULL);
    g_petsc_ready = 1;
    atexit(petsc_at_exit);
    return MPM_OK;
}

const char *petsc_library_version(void)
{
    static char version[32];
    PetscInt major = 0, minor = 0, subminor = 0;
    PetscGetVersionNumber(&major, &minor, &subminor, NULL); /* the library's, not the header's */
    snprintf(version, sizeof version, "%d.%d.%d", (int)major, (int)minor, (int)subminor);
    return version;
}

/* ---- options ---- */

/* PETSc's object prefixes that the adapter passes through */
static int is_petsc_key(const char *key)
{
    static const char *const namespaces[] = {"ksp_", "pc_", "mg_", "sub_", "mat_"};
    for (size_t i = 0; i < sizeof namespaces / sizeof namespaces[0]; ++i)
        if (!strncmp(key, namespaces[i], strlen(namespaces[i]))) return 1;
    return 0;
}

static int add_key(Petsc *s, const char *key, const char *value)
{
    if (s->n_keys >= PETSC_MAX_KEYS) {
        mpm_error(MPM_EINPUT, "petsc: more than %d PETSc options", PETSC_MAX_KEYS);
        return -1;
    }
    snprintf(s->key[s->n_keys], sizeof s->key[0], "%s", key);
    snprintf(s->value[s->n_keys], sizeof s->value[0], "%s", value);
    return s->n_keys++;
}

static void option_name(const Petsc *s, int i, char *name, size_t cap)
{
    snprintf(name, cap, "-%s%s", s->prefix, s->key[i]);
}

/* Puts the instance's options into PETSc's database (once: they stay until destroy). */
static int set_options(Petsc *s)
{
    if (s->options_set) return MPM_OK;
    int st = petsc_library_startup();
    for (int i = 0; i < s->n_keys && !st; ++i) {
        char name[SOLVER_OPT_KEY + 32];
        option_name(s, i, name, sizeof name);
        st = pk(PetscOptionsSetValue(NULL, name, s->value[i]), MPM_EINPUT, name);
    }
    if (!st) s->options_set = 1;
    return st;
}

static void clear_options(Petsc *s)
{
    if (!s->options_set || !g_petsc_ready) return;
    for (int i = 0; i < s->n_keys; ++i) {
        char name[SOLVER_OPT_KEY + 32];
        option_name(s, i, name, sizeof name);
        PetscOptionsClearValue(NULL, name);
    }
    s->options_set = 0;
}

/* ---- the matrix ---- */

static void destroy_solver(Petsc *s)
{
    if (s->ksp) KSPDestroy(&s->ksp);
    if (s->b) VecDestroy(&s->b);
    if (s->x) VecDestroy(&s->x);
    s->ksp = NULL;
    s->b = s->x = NULL;
    s->ready = 0;
}

static void destroy_matrix(Petsc *s)
{
    if (s->A) MatDestroy(&s->A);
    s->A = NULL;
    s->pattern_id = 0;
    s->nnzb = -1;
}

/* A's structure from H's pattern (a new Mat): the block rows as they are
 * (baij), or each block row as three scalar rows of 3 entries a block (aij). */
static int build_structure(Petsc *s, const Bsr *H)
{
    destroy_matrix(s);
    const int n = H->n, rows = s->baij ? n : 3 * n;
    const int64_t entries = s->baij ? H->nnzb : 9 * H->nnzb;
    if (rows + 1 > s->cap_ia) {
        PetscInt *p = realloc(s->ia, sizeof(PetscInt) * (size_t)(rows + 1));
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc (%d rows)", rows);
        s->ia = p;
        s->cap_ia = rows + 1;
    }
    if (entries > s->cap_ja) {
        PetscInt *p = realloc(s->ja, sizeof(PetscInt) * (size_t)entries);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc (%lld entries)", (long long)entries);
        s->ja = p;
        s->cap_ja = entries;
    }
    if (s->baij) {
        for (int i = 0; i <= n; ++i) s->ia[i] = (PetscInt)H->row_ptr[i];
        for (int64_t k = 0; k < H->nnzb; ++k) s->ja[k] = H->col[k];
    } else {
        s->ia[3 * n] = (PetscInt)(9 * H->row_ptr[n]);
#pragma omp parallel for schedule(static)
        for (int R = 0; R < n; ++R) {
            const int64_t k0 = H->row_ptr[R], len = H->row_ptr[R + 1] - k0;
            for (int a = 0; a < 3; ++a) {
                int64_t q = 9 * k0 + 3 * len * a; /* scalar row 3R+a starts here */
                s->ia[3 * R + a] = (PetscInt)q;
                for (int64_t k = k0; k < k0 + len; ++k)
                    for (int b = 0; b < 3; ++b) s->ja[q++] = 3 * H->col[k] + b;
            }
        }
    }
    int st = pk(MatCreate(PETSC_COMM_SELF, &s->A), MPM_EINTERNAL, "MatCreate");
    if (!st) st = pk(MatSetSizes(s->A, 3 * n, 3 * n, 3 * n, 3 * n), MPM_EINTERNAL, "MatSetSizes");
    if (!st) st = pk(MatSetType(s->A, s->baij ? MATSEQBAIJ : MATSEQAIJ), MPM_EINTERNAL, "MatSetType");
    /* 3 unknowns a node: GAMG aggregates nodes, the near-null space is per node */
    if (!st) st = pk(MatSetBlockSize(s->A, 3), MPM_EINTERNAL, "MatSetBlockSize");
    /* zero values: the structure only; fill_values writes them */
    if (!st && s->baij)
        st = pk(MatSeqBAIJSetPreallocationCSR(s->A, 3, s->ia, s->ja, NULL), MPM_EINTERNAL,
                "MatSeqBAIJSetPreallocationCSR");
    if (!st && !s->baij)
        st = pk(MatSeqAIJSetPreallocationCSR(s->A, s->ia, s->ja, NULL), MPM_EINTERNAL, "MatSeqAIJSetPreallocationCSR");
    if (!st) {
        MatInfo info;
        st = pk(MatGetInfo(s->A, MAT_LOCAL, &info), MPM_EINTERNAL, "MatGetInfo");
        /* fill_values relies on PETSc keeping exactly the Hessian's entries in this order */
        if (!st && (int64_t)info.nz_used != 9 * H->nnzb)
            st = mpm_error(MPM_EINTERNAL, "petsc: the Mat holds %.0f entries, the Hessian %lld", info.nz_used,
                           (long long)(9 * H->nnzb));
    }
    if (st) {
        destroy_matrix(s);
        return st;
    }
    s->n = n;
    s->nnzb = H->nnzb;
    s->pattern_id = H->pattern_id;
    return MPM_OK;
}

/* H's values into A's value array, in the order build_structure laid out:
 * baij: block k to block k, transposed (BAIJ blocks are column-major); aij:
 * row a of block k to scalar row 3R+a. */
static int fill_values(Petsc *s, const Bsr *H)
{
    PetscScalar *a = NULL;
    int st = s->baij ? pk(MatSeqBAIJGetArray(s->A, &a), MPM_EINTERNAL, "MatSeqBAIJGetArray")
                     : pk(MatSeqAIJGetArray(s->A, &a), MPM_EINTERNAL, "MatSeqAIJGetArray");
    if (st) return st;
    const double *v = H->val;
    if (s->baij) {
#pragma omp parallel for schedule(static)
        for (int64_t k = 0; k < H->nnzb; ++k) {
            const double *src = v + 9 * k;
            PetscScalar *dst = a + 9 * k;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) dst[3 * c + r] = src[3 * r + c];
        }
    } else {
        const int n = H->n;
#pragma omp parallel for schedule(static)
        for (int R = 0; R < n; ++R) {
            const int64_t k0 = H->row_ptr[R], len = H->row_ptr[R + 1] - k0;
            for (int r = 0; r < 3; ++r) {
                PetscScalar *dst = a + 9 * k0 + 3 * len * r;
                for (int64_t k = k0; k < k0 + len; ++k, dst += 3) {
                    const double *src = v + 9 * k + 3 * r;
                    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2];
                }
            }
        }
    }
    st = s->baij ? pk(MatSeqBAIJRestoreArray(s->A, &a), MPM_EINTERNAL, "MatSeqBAIJRestoreArray")
                 : pk(MatSeqAIJRestoreArray(s->A, &a), MPM_EINTERNAL, "MatSeqAIJRestoreArray");
    /* new values under the same Mat: PCSetUp sees a changed operator */
    if (!st) st = pk(PetscObjectStateIncrease((PetscObject)s->A), MPM_EINTERNAL, "PetscObjectStateIncrease");
    return st;
}

static int same_pattern(const Petsc *s, const Bsr *H)
{
    return s->A && s->n == H->n && s->nnzb == H->nnzb && s->pattern_id == H->pattern_id;
}

/* The six rigid-body modes of the nodes (integer coordinates about their
 * centroid) as A's near-null space; across ranks (s->dist) the owned
 * nodes' modes about the whole scene's centroid. */
static int set_near_null_space(Petsc *s, int n, const int *coord)
{
    if (!s->rbm) return pk(MatSetNearNullSpace(s->A, NULL), MPM_EINTERNAL, "MatSetNearNullSpace");
    if (!coord) return mpm_error(MPM_EINTERNAL, "petsc: petsc_rbm=on needs node coordinates");
    const unsigned char *owned = s->dist ? s->owned : NULL;
    double c[4] = {0, 0, 0, 0}; /* coordinate sums and the node count */
    for (int i = 0; i < n; ++i)
        if (!owned || owned[i]) {
            for (int d = 0; d < 3; ++d) c[d] += coord[3 * i + d];
            c[3] += 1;
        }
    if (s->dist && MPI_Allreduce(MPI_IN_PLACE, c, 4, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD) != MPI_SUCCESS)
        return mpm_error(MPM_EINTERNAL, "petsc: MPI_Allreduce of the centroid failed");
    for (int d = 0; d < 3; ++d) c[d] /= c[3] > 0 ? c[3] : 1;
    const int rows = s->dist ? s->num.n_owned : n;
    Vec xyz = NULL;
    MatNullSpace nsp = NULL;
    PetscScalar *p = NULL;
    int st = s->dist ? pk(VecCreateMPI(PETSC_COMM_WORLD, 3 * rows, PETSC_DECIDE, &xyz), MPM_EINTERNAL, "VecCreateMPI")
                     : pk(VecCreateSeq(PETSC_COMM_SELF, 3 * rows, &xyz), MPM_EINTERNAL, "VecCreateSeq");
    if (!st) st = pk(VecSetBlockSize(xyz, 3), MPM_EINTERNAL, "VecSetBlockSize");
    if (!st) st = pk(VecGetArray(xyz, &p), MPM_EINTERNAL, "VecGetArray");
    if (!st) {
        int k = 0;
        for (int i = 0; i < n; ++i)
            if (!owned || owned[i]) {
                for (int d = 0; d < 3; ++d) p[3 * k + d] = coord[3 * i + d] - c[d];
                ++k;
            }
        st = pk(VecRestoreArray(xyz, &p), MPM_EINTERNAL, "VecRestoreArray");
    }
    if (!st) st = pk(MatNullSpaceCreateRigidBody(xyz, &nsp), MPM_EINTERNAL, "MatNullSpaceCreateRigidBody");
    if (!st) st = pk(MatSetNearNullSpace(s->A, nsp), MPM_EINTERNAL, "MatSetNearNullSpace");
    if (nsp) MatNullSpaceDestroy(&nsp);
    if (xyz) VecDestroy(&xyz);
    return st;
}

/* A new KSP on A, from the options; set up. `status` is what a PETSc error
 * becomes (MPM_EINPUT while create probes the options). */
static int build_solver(Petsc *s, int status)
{
    destroy_solver(s);
    const int N = 3 * (s->dist ? s->num.n_owned : s->n);
    const MPI_Comm comm = s->dist ? PETSC_COMM_WORLD : PETSC_COMM_SELF;
    int st = pk(KSPCreate(comm, &s->ksp), MPM_EINTERNAL, "KSPCreate");
    if (!st) st = pk(KSPSetOptionsPrefix(s->ksp, s->prefix), MPM_EINTERNAL, "KSPSetOptionsPrefix");
    if (!st) st = pk(KSPSetOperators(s->ksp, s->A, s->A), MPM_EINTERNAL, "KSPSetOperators");
    /* a zero guess: apply is M r, not a correction of z's old contents */
    if (!st) st = pk(KSPSetInitialGuessNonzero(s->ksp, PETSC_FALSE), MPM_EINTERNAL, "KSPSetInitialGuessNonzero");
    PC pc = NULL;
    if (!st && s->hier && !(st = pk(KSPGetPC(s->ksp, &pc), MPM_EINTERNAL, "KSPGetPC"))) {
        /* across ranks: the levels of the owned nodes, split by the run's decomposition */
        const PetscHierarchyRanks ranks = {s->comm, s->decomp, s->num.first, s->num.total};
        st = s->dist ? petsc_hierarchy_attach(s->hier, pc, s->num.n_owned, s->owned_coord, NULL, &ranks)
                     : petsc_hierarchy_attach(s->hier, pc, s->n, s->coord, s->coloring, NULL);
    }
    if (!st) st = pk(KSPSetFromOptions(s->ksp), status, "KSPSetFromOptions");
    if (!st && s->hier) st = petsc_hierarchy_configure(s->hier, pc);
    if (!st) st = pk(KSPSetUp(s->ksp), status == MPM_EINPUT ? MPM_EINPUT : MPM_ENUMERIC, "KSPSetUp");
    /* vectors without storage: apply places the caller's arrays */
    if (!st && s->dist) {
        st = pk(VecCreateMPIWithArray(comm, 3, N, PETSC_DECIDE, NULL, &s->b), MPM_EINTERNAL, "VecCreateMPIWithArray");
        if (!st) st = pk(VecCreateMPIWithArray(comm, 3, N, PETSC_DECIDE, NULL, &s->x), MPM_EINTERNAL, "VecCreateMPIWithArray");
    } else if (!st) {
        st = pk(VecCreateSeqWithArray(comm, 3, N, NULL, &s->b), MPM_EINTERNAL, "VecCreateSeqWithArray");
        if (!st) st = pk(VecCreateSeqWithArray(comm, 3, N, NULL, &s->x), MPM_EINTERNAL, "VecCreateSeqWithArray");
    }
    if (st) {
        destroy_solver(s);
        return st;
    }
    s->ready = 1;
    return MPM_OK;
}

/* A full setup on H: the structure when the pattern is new, the values, the
 * near-null space and a new KSP. */
static int setup_on(Petsc *s, const Bsr *H, const int *coord, const NodeColoring *coloring, int status)
{
    destroy_solver(s);
    s->dist = 0;
    s->coord = coord;
    s->coloring = coloring;
    int st = set_options(s);
    if (!st && !same_pattern(s, H)) st = build_structure(s, H);
    if (!st) st = fill_values(s, H);
    if (!st) st = set_near_null_space(s, H->n, coord);
    if (!st) st = build_solver(s, status);
    return st;
}

/* ---- across ranks ---- */

/* Room for the numbering, one block row and the packed owned vectors. */
static int reserve_ranks(Petsc *s, const Bsr *H)
{
    if (H->n > s->cap_gid) {
        int *p = realloc(s->gid, sizeof(int) * (size_t)H->n);
        if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc node numbers (%d nodes)", H->n);
        s->gid = p;
        s->cap_gid = H->n;
    }
    int64_t row = 1;
    for (int i = 0; i < H->n; ++i) row = H->row_ptr[i + 1] - H->row_ptr[i] > row ? H->row_ptr[i + 1] - H->row_ptr[i] : row;
    if (row > s->cap_row) {
        PetscInt *c = realloc(s->row_cols, sizeof(PetscInt) * (size_t)row);
        if (c) s->row_cols = c;
        PetscScalar *v = c ? realloc(s->row_vals, sizeof(PetscScalar) * 9 * (size_t)row) : NULL;
        if (!v) return mpm_error(MPM_EINTERNAL, "out of memory: petsc block row (%lld blocks)", (long long)row);
        s->row_vals = v;
        s->cap_row = row;
    }
    if (3 * (int64_t)H->n > s->cap_owned) {
        double *r = realloc(s->r_owned, sizeof(double) * 3 * (size_t)H->n);
        if (r) s->r_owned = r;
        double *z = r ? realloc(s->z_owned, sizeof(double) * 3 * (size_t)H->n) : NULL;
        if (!z) return mpm_error(MPM_EINTERNAL, "out of memory: petsc owned vectors (%d nodes)", H->n);
        s->z_owned = z;
        int *c = s->hier ? realloc(s->owned_coord, sizeof(int) * 3 * (size_t)H->n) : s->owned_coord;
        if (s->hier && !c) return mpm_error(MPM_EINTERNAL, "out of memory: petsc owned nodes (%d nodes)", H->n);
        s->owned_coord = c;
        s->cap_owned = 3 * (int64_t)H->n;
    }
    return MPM_OK;
}

/* Block row i of H with global columns into s->row_cols and, when values,
 * its blocks into s->row_vals as MatSetValuesBlocked reads them (row
 * oriented: the three scalar rows of the block row, each across every
 * block); returns the block count. */
static PetscInt gather_row(Petsc *s, const Bsr *H, int i, int values)
{
    const int64_t k0 = H->row_ptr[i], len = H->row_ptr[i + 1] - k0;
    for (int64_t k = 0; k < len; ++k) {
        s->row_cols[k] = s->gid[H->col[k0 + k]];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                s->row_vals[3 * len * r + 3 * k + c] = values ? H->val[9 * (k0 + k) + 3 * r + c] : 0.0;
    }
    return (PetscInt)len;
}

/* Every rank's part of H into A: ghost rows' blocks go to their owners in
 * PETSc's assembly, where they are added to the owner's own. */
static int fill_values_ranks(Petsc *s, const Bsr *H)
{
    int st = pk(MatZeroEntries(s->A), MPM_EINTERNAL, "MatZeroEntries");
    for (int i = 0; i < H->n && !st; ++i) {
        const PetscInt row = s->gid[i], len = gather_row(s, H, i, 1);
        st = pk(MatSetValuesBlocked(s->A, 1, &row, len, s->row_cols, s->row_vals, ADD_VALUES), MPM_EINTERNAL,
                "MatSetValuesBlocked");
    }
    if (!st) st = pk(MatAssemblyBegin(s->A, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyBegin");
    if (!st) st = pk(MatAssemblyEnd(s->A, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyEnd");
    return st;
}

/* A parallel Mat (MATBAIJ or MATAIJ of block size 3: MPI or Seq by the
 * rank count) over the owned rows, its nonzero structure the union of
 * every rank's pattern (counted by a MATPREALLOCATOR pass, so no row is
 * under- or over-allocated). */
static int build_structure_ranks(Petsc *s, const Bsr *H)
{
    destroy_matrix(s);
    const PetscInt local = 3 * s->num.n_owned, global = 3 * s->num.total;
    Mat pre = NULL;
    int st = pk(MatCreate(PETSC_COMM_WORLD, &pre), MPM_EINTERNAL, "MatCreate");
    if (!st) st = pk(MatSetType(pre, MATPREALLOCATOR), MPM_EINTERNAL, "MatSetType");
    if (!st) st = pk(MatSetSizes(pre, local, local, global, global), MPM_EINTERNAL, "MatSetSizes");
    if (!st) st = pk(MatSetBlockSize(pre, 3), MPM_EINTERNAL, "MatSetBlockSize");
    if (!st) st = pk(MatSetUp(pre), MPM_EINTERNAL, "MatSetUp");
    for (int i = 0; i < H->n && !st; ++i) {
        const PetscInt row = s->gid[i], len = gather_row(s, H, i, 0);
        st = pk(MatSetValuesBlocked(pre, 1, &row, len, s->row_cols, s->row_vals, INSERT_VALUES), MPM_EINTERNAL,
                "MatSetValuesBlocked");
    }
    if (!st) st = pk(MatAssemblyBegin(pre, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyBegin");
    if (!st) st = pk(MatAssemblyEnd(pre, MAT_FINAL_ASSEMBLY), MPM_EINTERNAL, "MatAssemblyEnd");
    if (!st) st = pk(MatCreate(PETSC_COMM_WORLD, &s->A), MPM_EINTERNAL, "MatCreate");
    if (!st) st = pk(MatSetSizes(s->A, local, local, global, global), MPM_EINTERNAL, "MatSetSizes");
    if (!st) st = pk(MatSetType(s->A, s->baij ? MATBAIJ : MATAIJ), MPM_EINTERNAL, "MatSetType");
    if (!st) st = pk(MatSetBlockSize(s->A, 3), MPM_EINTERNAL, "MatSetBlockSize");
    if (!st) st = pk(MatPreallocatorPreallocate(pre, PETSC_TRUE, s->A), MPM_EINTERNAL, "MatPreallocatorPreallocate");
    /* a block outside the counted structure is a bug, not a reallocation */
    if (!st) st = pk(MatSetOption(s->A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), MPM_EINTERNAL, "MatSetOption");
    if (pre) MatDestroy(&pre);
    if (st) destroy_matrix(s);
    return st;
}

/* A full setup across ranks: numbering, structure, values, near-null
 * space, a KSP on PETSC_COMM_WORLD. Every rank calls it (a setup is
 * collective); a local failure before the first PETSc collective fails
 * every rank. */
static int setup_ranks(Petsc *s, const InvSetupInput *in)
{
    const Bsr *H = in->H;
    s->dist = 1;
    s->owned = in->owned;
    s->n = H->n;
    s->coord = in->coord;
    s->coloring = in->coloring;
    int st = set_options(s);
    if (!st) st = reserve_ranks(s, H);
    if (!st && !in->coord) st = mpm_error(MPM_EINTERNAL, "petsc: needs node coordinates across ranks");
    if ((st = comm_agree(in->comm, st))) return st;
    if ((st = dist_node_numbering(in->comm, in->owned, H->n, s->gid, &s->num))) return st;
    s->comm = in->comm;
    s->decomp = in->decomp;
    for (int i = 0, k = 0; s->hier && i < H->n; ++i) /* sorted by node_order_key, as the local nodes are */
        if (in->owned[i]) memcpy(s->owned_coord + 3 * (size_t)k++, in->coord + 3 * (size_t)i, 3 * sizeof(int));
    st = build_structure_ranks(s, H);
    if (!st) st = fill_values_ranks(s, H);
    if (!st) st = set_near_null_space(s, s->n, in->coord);
    if (!st) st = build_solver(s, MPM_EINTERNAL);
    return st;
}

/* r's owned entries packed (across ranks), or r itself */
static const double *owned_part(Petsc *s, const double *r, double *packed)
{
    if (!s->dist) return r;
    int k = 0;
    for (int i = 0; i < s->n; ++i)
        if (s->owned[i]) memcpy(packed + 3 * (size_t)k++, r + 3 * (size_t)i, 3 * sizeof(double));
    return packed;
}

/* the packed owned entries back into z, zeros at the ghosts */
static void unpack_owned(const Petsc *s, const double *packed, double *z)
{
    int k = 0;
    for (int i = 0; i < s->n; ++i) {
        if (s->owned[i]) memcpy(z + 3 * (size_t)i, packed + 3 * (size_t)k++, 3 * sizeof(double));
        else memset(z + 3 * (size_t)i, 0, 3 * sizeof(double));
    }
}

/* ---- the probe: the options set up once on a small matrix at create ---- */

/* An m^3 block of nodes, each coupled to its 26 neighbours by a spring
 * along the offset (k d d^T / |d|^2) plus a unit mass: symmetric positive
 * definite, with elasticity's 3x3 coupling. */
static int probe_matrix(Bsr *A, int **coord_out)
{
    const int m = PROBE_NODES_PER_AXIS, n = m * m * m;
    memset(A, 0, sizeof *A);
    int st = bsr_reserve(A, n, 27 * (int64_t)n);
    int *coord = malloc(sizeof(int) * 3 * (size_t)n);
    if (st || !coord) {
        free(coord);
        bsr_free(A);
        return st ? st : mpm_error(MPM_EINTERNAL, "out of memory: petsc probe");
    }
    int64_t k = 0;
    for (int i = 0; i < n; ++i) {
        const int x = i % m, y = (i / m) % m, z = i / (m * m);
        coord[3 * i] = x, coord[3 * i + 1] = y, coord[3 * i + 2] = z;
        A->row_ptr[i] = k;
        int64_t diag = -1;
        double dsum[9] = {0};
        for (int dz = -1; dz <= 1; ++dz) /* increasing neighbour index: sorted columns */
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int X = x + dx, Y = y + dy, Z = z + dz;
                    if (X < 0 || Y < 0 || Z < 0 || X >= m || Y >= m || Z >= m) continue;
                    A->col[k] = X + m * (Y + m * Z);
                    double *blk = A->val + 9 * k;
                    const double d[3] = {dx, dy, dz}, len2 = dx * dx + dy * dy + dz * dz;
                    for (int r = 0; r < 3; ++r)
                        for (int c = 0; c < 3; ++c) {
                            const double kk = len2 > 0 ? 100.0 * d[r] * d[c] / len2 : 0.0;
                            blk[3 * r + c] = -kk;
                            dsum[3 * r + c] += kk;
                        }
                    if (len2 == 0) diag = k;
                    ++k;
                }
        for (int e = 0; e < 9; ++e) A->val[9 * diag + e] = dsum[e] + (e % 4 == 0 ? 1.0 : 0.0);
    }
    A->row_ptr[n] = k;
    A->nnzb = k;
    bsr_update_pattern_id(A);
    *coord_out = coord;
    return MPM_OK;
}

/* The options set up once on the probe matrix, and every given one used. */
static int probe_options(Petsc *s)
{
    Bsr A;
    int *coord = NULL;
    int st = probe_matrix(&A, &coord);
    if (st) return st;
    st = setup_on(s, &A, coord, NULL, MPM_EINPUT);
    if (!st && s->complete) {
        /* a solve, so that the options a KSPSolve reads are read too */
        Vec b = NULL, x = NULL;
        st = pk(MatCreateVecs(s->A, &x, &b), MPM_EINTERNAL, "MatCreateVecs");
        if (!st) st = pk(VecSet(b, 1.0), MPM_EINTERNAL, "VecSet");
        if (!st) st = pk(KSPSolve(s->ksp, b, x), MPM_EINPUT, "KSPSolve");
        if (b) VecDestroy(&b);
        if (x) VecDestroy(&x);
    }
    for (int g = 0; g < s->n_given && !st; ++g) {
        const int i = s->given[g];
        char name[SOLVER_OPT_KEY + 32];
        PetscBool used = PETSC_FALSE;
        snprintf(name, sizeof name, "%s%s", s->prefix, s->key[i]);
        st = pk(PetscOptionsUsed(NULL, name, &used), MPM_EINTERNAL, "PetscOptionsUsed");
        if (!st && !used)
            st = mpm_error(MPM_EINPUT,
                           "solver option %s=%s: PETSc did not use it with ksp_type=%s, pc_type=%s (see -help of "
                           "that KSP and PC)",
                           s->key[i], s->value[i], s->value[0], s->value[1]);
    }
    destroy_solver(s);
    destroy_matrix(s);
    bsr_free(&A);
    free(coord);
    return st;
}

/* ---- the ops ---- */

static void petsc_destroy(InvApprox *self)
{
    if (!self) return;
    Petsc *s = (Petsc *)self;
    destroy_solver(s);
    destroy_matrix(s);
    clear_options(s);
    petsc_hierarchy_destroy(s->hier);
    free(s->r_proj);
    free(s->ia);
    free(s->ja);
    free(s->gid);
    free(s->row_cols);
    free(s->row_vals);
    free(s->r_owned);
    free(s->z_owned);
    free(s->owned_coord);
    free(s);
}

/* The options of petsc_hierarchy=linear|quadratic (HOT's levels as a PCMG),
 * read only then, so that they are unknown options without it: the in-house
 * mg inverse's options and defaults under the prefix petsc_. */
static int hierarchy_options(SolverOptions *opt, const char *kind, PetscHierarchyOptions *o)
{
    int st = MPM_OK;
    o->kind = !strcmp(kind, "quadratic") ? MG_EMBED_QUADRATIC : MG_EMBED_LINEAR;
    o->max_levels = solver_opt_int(opt, "petsc_levels", 3, 1, MG_MAX_LEVELS, &st);
    o->sweeps = solver_opt_int(opt, "petsc_sweeps", 1, 1, 100, &st);
    o->min_coarse_nodes = solver_opt_int(opt, "petsc_min_coarse_nodes", 300, 1, 1000000000, &st);
    o->coarse_max_iters = solver_opt_int(opt, "petsc_coarse_max_iters", 10000, 1, 1000000000, &st);
    o->coarse_tol = solver_opt_number(opt, "petsc_coarse_tol", 0.5, &st);
    const int exact = solver_opt_int(opt, "petsc_coarse_exact", 0, 0, 1, &st);
    const char *smoother = solver_opt_string(opt, "petsc_smoother", "sgs");
    if (st) return st;
    if (!(o->coarse_tol > 0 && o->coarse_tol < 1))
        return mpm_error(MPM_EINPUT, "solver option petsc_coarse_tol=%g: expected 0 < tol < 1", o->coarse_tol);
    if (exact) o->coarse_tol = 1e-12;
    if (!strcmp(smoother, "sgs")) o->mpm_smoother = 1;
    else if (!strcmp(smoother, "petsc")) o->mpm_smoother = 0;
    else return mpm_error(MPM_EINPUT, "solver option petsc_smoother=%s: expected sgs or petsc", smoother);
    /* what the hierarchy sets itself is not also taken from PETSc's options */
    const char *ksp_type = solver_opt_string(opt, "ksp_type", "preonly");
    const char *pc_type = solver_opt_string(opt, "pc_type", "mg");
    if (strcmp(ksp_type, "preonly"))
        return mpm_error(MPM_EINPUT, "solver option ksp_type=%s: petsc_hierarchy is one V-cycle (ksp_type=preonly)",
                         ksp_type);
    if (strcmp(pc_type, "mg"))
        return mpm_error(MPM_EINPUT, "solver option pc_type=%s: petsc_hierarchy builds a PCMG (pc_type=mg)", pc_type);
    for (int i = 0; opt && i < opt->n; ++i) {
        const char *key = opt->key[i];
        if (!strncmp(key, "mg_coarse_", 10) || (o->mpm_smoother && !strncmp(key, "mg_levels_", 10)))
            return mpm_error(MPM_EINPUT, "solver option %s: petsc_hierarchy sets %s itself%s", key,
                             key[3] == 'c' ? "the coarse solve (HOT's block-Jacobi CG)" : "the smoothers",
                             key[3] == 'c' ? "" : " with petsc_smoother=sgs (petsc_smoother=petsc takes mg_levels_ options)");
        if (!strcmp(key, "petsc_mat_type") || !strcmp(key, "petsc_rbm"))
            return mpm_error(MPM_EINPUT, "solver option %s: not used with petsc_hierarchy (an AIJ matrix, no "
                             "near-null space)", key);
    }
    return MPM_OK;
}

static int petsc_create(SolverOptions *opt, InvApprox **out)
{
    const char *hierarchy = solver_opt_string(opt, "petsc_hierarchy", "none");
    PetscHierarchyOptions hopt = {0};
    int hier = strcmp(hierarchy, "none") != 0;
    if (hier && strcmp(hierarchy, "linear") && strcmp(hierarchy, "quadratic"))
        return mpm_error(MPM_EINPUT, "solver option petsc_hierarchy=%s: expected none, linear or quadratic", hierarchy);
    int st = hier ? hierarchy_options(opt, hierarchy, &hopt) : MPM_OK;
    if (st) return st;
    const char *ksp_type = solver_opt_string(opt, "ksp_type", "preonly");
    const char *pc_type = solver_opt_string(opt, "pc_type", hier ? "mg" : "gamg");
    const char *rbm = hier ? "off" : solver_opt_string(opt, "petsc_rbm", "on");
    const char *mat_type = hier ? "aij" : solver_opt_string(opt, "petsc_mat_type", "aij");
    if (strcmp(mat_type, "aij") && strcmp(mat_type, "baij"))
        return mpm_error(MPM_EINPUT, "solver option petsc_mat_type=%s: expected aij or baij", mat_type);
    int r;
    if (!strcmp(rbm, "on")) r = 1;
    else if (!strcmp(rbm, "off")) r = 0;
    else return mpm_error(MPM_EINPUT, "solver option petsc_rbm=%s: expected on or off", rbm);
    Petsc *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: petsc");
    s->base.ops = &inv_petsc_ops;
    s->rbm = r;
    s->baij = !strcmp(mat_type, "baij");
    if (hier && (st = petsc_hierarchy_create(&hopt, &s->hier))) {
        free(s);
        return st;
    }
    s->nnzb = -1;
    snprintf(s->prefix, sizeof s->prefix, "mpm%d_", g_next_prefix++);
    add_key(s, "ksp_type", ksp_type);
    add_key(s, "pc_type", pc_type);
    for (int i = 0; opt && i < opt->n && !st; ++i) {
        const char *key = opt->key[i];
        if (!is_petsc_key(key) || !strcmp(key, "ksp_type") || !strcmp(key, "pc_type")) continue;
        for (const char *c = key; *c && !st; ++c)
            if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '_'))
                st = mpm_error(MPM_EINPUT, "solver option %s: a PETSc option name is letters, digits and _",
                               key);
        if (!st && (strstr(key, "_view") || strstr(key, "monitor")))
            st = mpm_error(MPM_EINPUT,
                           "solver option %s: PETSc options that print are not passed (the run records the KSP's "
                           "view itself)",
                           key);
        if (st) break;
        const char *value = solver_opt_string(opt, key, ""); /* asked: recorded in run.json, not unknown */
        int k = add_key(s, key, value);
        if (k < 0) st = MPM_EINPUT;
        else s->given[s->n_given++] = k;
    }
    /* given ksp_type and pc_type are checked too (a misspelt type is refused by PETSc) */
    for (int i = 0; opt && i < opt->n; ++i)
        if (!strcmp(opt->key[i], "ksp_type") || !strcmp(opt->key[i], "pc_type"))
            s->given[s->n_given++] = !strcmp(opt->key[i], "ksp_type") ? 0 : 1;
    s->complete = strcmp(ksp_type, "preonly") != 0;
    /* a KSP to its tolerance is not a fixed linear map; one PCApply is
     * (symmetric for the symmetric PCs the presets use) */
    s->base.caps = INV_NEEDS_HESSIAN | INV_POSITIVE | INV_DISTRIBUTED |
                   (s->complete ? INV_VARIABLE | INV_INNER_ITERS : INV_SYMMETRIC);
    if (hier) { /* as the in-house mg: an adaptive coarse CG, unless to 1e-12 (then symmetric) */
        s->base.caps = INV_NEEDS_HESSIAN | INV_POSITIVE | INV_INNER_ITERS | INV_DISTRIBUTED |
                       (hopt.coarse_tol <= 1e-12 ? INV_SYMMETRIC : INV_VARIABLE);
        s->base.flexible = hopt.max_levels > 1 && solver_opt_int(opt, "flexible", 1, 0, 1, &st);
    }
    /* Debian's PETSc runs on one thread; only the copy into it is threaded */
    s->base.setup_threads = s->base.apply_threads = 1;
    if (!st && s->n_given > 0 && (st = probe_options(s)) && !strstr(mpm_last_error(), "solver option")) {
        /* PETSc refused one of them: name what was given */
        char given[512] = "";
        size_t len = 0;
        for (int g = 0; g < s->n_given && len < sizeof given; ++g)
            len += (size_t)snprintf(given + len, sizeof given - len, "%s%s=%s", g ? "," : "", s->key[s->given[g]],
                                    s->value[s->given[g]]);
        st = mpm_error_context(st, "solver options %s", given);
    }
    if (st) {
        petsc_destroy(&s->base);
        return st;
    }
    *out = &s->base;
    return MPM_OK;
}

/* apply is P M P with P the Dirichlet projection: GAMG's aggregates take
 * the Dirichlet nodes in (their rows are decoupled identity rows, not
 * dropped), so its coarse corrections reach them; projecting the input and
 * the output keeps the map symmetric and zero there */
static int take_projection(Petsc *s, const InvSetupInput *in)
{
    s->proj = in->proj;
    const int64_t len = 3 * (int64_t)in->n_nodes;
    if (!s->proj || len <= s->cap_r) return MPM_OK;
    double *p = realloc(s->r_proj, sizeof(double) * (size_t)len);
    if (!p) return mpm_error(MPM_EINTERNAL, "out of memory: petsc (%lld unknowns)", (long long)len);
    s->r_proj = p;
    s->cap_r = len;
    return MPM_OK;
}

static int petsc_setup(InvApprox *self, const InvSetupInput *in)
{
    Petsc *s = (Petsc *)self;
    self->stats = (InvStats){0};
    destroy_solver(s);
    const Bsr *H = in->H;
    if (!H) return mpm_error(MPM_EINTERNAL, "petsc: needs the assembled Hessian (matrix-free PN is not supported)");
    if (H->n != in->n_nodes)
        return mpm_error(MPM_EINTERNAL, "petsc: Hessian has %d block rows but the problem %d nodes", H->n, in->n_nodes);
    if (3 * (int64_t)H->n > (int64_t)0x7fffffff || 9 * H->nnzb > (int64_t)0x7fffffff)
        return mpm_error(MPM_EINTERNAL, "petsc: Hessian too large for PETSc's 32-bit indices (%d nodes, %lld blocks)",
                         H->n, (long long)H->nnzb);
    if (in->comm) {
        int st = setup_ranks(s, in);
        if (!st) st = take_projection(s, in);
        if (st) {
            destroy_solver(s);
            destroy_matrix(s);
        }
        return st;
    }
    if (H->n == 0) {
        destroy_matrix(s);
        s->n = 0;
        s->ready = 1;
        return MPM_OK;
    }
    int st = setup_on(s, H, in->coord, in->coloring, MPM_EINTERNAL);
    if (!st) st = take_projection(s, in);
    if (st) {
        destroy_solver(s);
        destroy_matrix(s); /* the next setup starts afresh */
    }
    return st;
}

/* Setup reuse (inverse_approx.h): values = 1 refreshes (the new values into
 * the kept Mat, the kept KSP set up again on them: PETSc's
 * SAME_NONZERO_PATTERN path); values = 0 keeps everything (PETSc holds its
 * own copy of the matrix, so a lagged preconditioner stays the earlier one). */
static int petsc_reuse(InvApprox *self, const InvSetupInput *in, int values, int *refreshed)
{
    Petsc *s = (Petsc *)self;
    *refreshed = 0;
    if (!in->H || in->H->n != s->n) return mpm_error(MPM_EINTERNAL, "petsc: reused for a different matrix");
    int st = take_projection(s, in); /* the step's pointers may have moved */
    if (st || s->n == 0 || !values) return st;
    if (!s->ksp || (!s->dist && !same_pattern(s, in->H)))
        return mpm_error(MPM_EINTERNAL, "petsc: reused without a matching setup");
    st = s->dist ? fill_values_ranks(s, in->H) : fill_values(s, in->H);
    if (!st) st = pk(KSPSetOperators(s->ksp, s->A, s->A), MPM_EINTERNAL, "KSPSetOperators");
    if (!st) st = pk(KSPSetUp(s->ksp), MPM_ENUMERIC, "KSPSetUp");
    if (st) {
        destroy_solver(s);
        destroy_matrix(s);
        return st;
    }
    *refreshed = 1;
    return MPM_OK;
}

static int petsc_apply(InvApprox *self, const double *r, double *z)
{
    Petsc *s = (Petsc *)self;
    if (s->n == 0 && s->ready) return MPM_OK;
    if (!s->ready) return mpm_error(MPM_EINTERNAL, "petsc: apply without a successful setup");
    /* HOT's levels: the input and output as the in-house V-cycle has them
     * (projected only when the hierarchy is one level, a plain PCG) */
    const int project = s->proj && (!s->hier || petsc_hierarchy_levels(s->hier) == 1);
    if (project) {
        memcpy(s->r_proj, r, sizeof(double) * 3 * (size_t)s->n);
        projection_apply(s->proj, s->r_proj);
        r = s->r_proj;
    }
    int st = pk(VecPlaceArray(s->b, owned_part(s, r, s->r_owned)), MPM_EINTERNAL, "VecPlaceArray");
    if (!st) st = pk(VecPlaceArray(s->x, s->dist ? s->z_owned : z), MPM_EINTERNAL, "VecPlaceArray");
    if (st) return st;
    if (!s->complete) {
        PC pc = NULL;
        st = pk(KSPGetPC(s->ksp, &pc), MPM_EINTERNAL, "KSPGetPC");
        if (!st && s->hier) st = petsc_hierarchy_prepare(s->hier, s->dist ? s->r_owned : r);
        if (!st) st = pk(PCApply(pc, s->b, s->x), MPM_ENUMERIC, "PCApply");
        if (!st && s->hier) st = petsc_hierarchy_finish(s->hier, &self->stats.inner_iters);
    } else {
        st = pk(KSPSolve(s->ksp, s->b, s->x), MPM_ENUMERIC, "KSPSolve");
        PetscInt its = 0;
        KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
        if (!st) st = pk(KSPGetIterationNumber(s->ksp, &its), MPM_EINTERNAL, "KSPGetIterationNumber");
        if (!st) st = pk(KSPGetConvergedReason(s->ksp, &reason), MPM_EINTERNAL, "KSPGetConvergedReason");
        self->stats.inner_iters += its;
        /* running out of iterations still gives a usable approximation;
         * a breakdown or a non-finite residual does not */
        if (!st && reason < 0 && reason != KSP_DIVERGED_ITS)
            st = mpm_error(MPM_ENUMERIC, "petsc: KSPSolve diverged (%s) after %d iterations",
                           KSPConvergedReasons[reason], (int)its);
    }
    VecResetArray(s->b);
    VecResetArray(s->x);
    if (!st && s->dist) unpack_owned(s, s->z_owned, z);
    if (!st && project) projection_apply(s->proj, z);
    return st;
}

int petsc_info(const InvApprox *self, int *levels, double *op_complexity)
{
    if (!self || self->ops != &inv_petsc_ops) return mpm_error(MPM_EINTERNAL, "petsc_info: not a petsc inverse approximation");
    const Petsc *s = (const Petsc *)self;
    if (!s->ksp) return mpm_error(MPM_EINTERNAL, "petsc_info: no solver (setup not done or failed)");
    PC pc = NULL;
    PetscBool multigrid = PETSC_FALSE;
    PetscInt nl = 1;
    PetscReal grid = 1.0, op = 1.0;
    int st = pk(KSPGetPC(s->ksp, &pc), MPM_EINTERNAL, "KSPGetPC");
    if (!st) st = pk(PetscObjectTypeCompareAny((PetscObject)pc, &multigrid, PCMG, PCGAMG, PCML, ""), MPM_EINTERNAL,
                     "PetscObjectTypeCompareAny");
    if (!st && multigrid) st = pk(PCMGGetLevels(pc, &nl), MPM_EINTERNAL, "PCMGGetLevels");
    if (!st && multigrid) st = pk(PCMGGetGridComplexity(pc, &grid, &op), MPM_EINTERNAL, "PCMGGetGridComplexity");
    if (st) return st;
    if (levels) *levels = (int)nl;
    if (op_complexity) *op_complexity = op;
    return MPM_OK;
}

int petsc_matvec(InvApprox *self, const double *x, double *y)
{
    if (!self || self->ops != &inv_petsc_ops) return mpm_error(MPM_EINTERNAL, "petsc_matvec: not a petsc inverse approximation");
    Petsc *s = (Petsc *)self;
    if (!s->A || !s->ready) return mpm_error(MPM_EINTERNAL, "petsc_matvec: no matrix (setup not done or failed)");
    int st = pk(VecPlaceArray(s->b, owned_part(s, x, s->r_owned)), MPM_EINTERNAL, "VecPlaceArray");
    if (!st) st = pk(VecPlaceArray(s->x, s->dist ? s->z_owned : y), MPM_EINTERNAL, "VecPlaceArray");
    if (!st) st = pk(MatMult(s->A, s->b, s->x), MPM_EINTERNAL, "MatMult");
    VecResetArray(s->b);
    VecResetArray(s->x);
    if (!st && s->dist) unpack_owned(s, s->z_owned, y);
    return st;
}

int petsc_view_text(const InvApprox *self, char *text, size_t cap)
{
    if (!self || self->ops != &inv_petsc_ops) return mpm_error(MPM_EINTERNAL, "petsc_view_text: not a petsc inverse approximation");
    const Petsc *s = (const Petsc *)self;
    if (!s->ksp || cap == 0) return mpm_error(MPM_EINTERNAL, "petsc_view_text: no solver (setup not done or failed)");
    /* KSPView through an ASCII viewer on a temporary file, read back */
    FILE *f = tmpfile();
    if (!f) return mpm_error(MPM_EINTERNAL, "petsc_view_text: no temporary file");
    PetscViewer v = NULL;
    /* on the KSP's communicator (collective across ranks; rank 0's file holds the text) */
    int st = pk(PetscViewerASCIIOpenWithFILE(PetscObjectComm((PetscObject)s->ksp), f, &v), MPM_EINTERNAL,
                "PetscViewerASCIIOpenWithFILE");
    if (!st) st = pk(KSPView(s->ksp, v), MPM_EINTERNAL, "KSPView");
    if (v) PetscViewerDestroy(&v);
    text[0] = '\0';
    if (!st) {
        fflush(f);
        rewind(f);
        size_t got = fread(text, 1, cap - 1, f);
        text[got] = '\0';
    }
    fclose(f);
    return st;
}

static void petsc_view(const InvApprox *self, FILE *f, InvView *out)
{
    const Petsc *s = (const Petsc *)self;
    int levels = 0;
    double cx = 0.0;
    if (s->ksp && petsc_info(self, &levels, &cx) != MPM_OK) {
        mpm_clear_error();
        levels = 0;
    }
    if (f)
        fprintf(f, "  PETSc %s KSP, %s PC: %d unknowns, %d levels, operator complexity %.3f\n", s->value[0], s->value[1],
                3 * s->n, levels, cx);
    inv_view_add(out, "levels", levels);
    inv_view_add(out, "operator_complexity", cx);
    if (s->hier) {
        PC pc = NULL;
        if (s->ksp) KSPGetPC(s->ksp, &pc);
        petsc_hierarchy_view(s->hier, pc, out);
    }
    inv_view_add(out, "library_threads", 1);
    if (out && s->ksp && petsc_view_text(self, out->library_view, sizeof out->library_view) != MPM_OK) {
        mpm_clear_error();
        out->library_view[0] = '\0';
    }
}

const InvApproxOps inv_petsc_ops = {"petsc",       "PETSc's KSP and PC (default: one GAMG V-cycle with rigid-body modes)",
                                    petsc_create,  petsc_setup,
                                    petsc_apply,   petsc_view,
                                    petsc_destroy, petsc_library_startup,
                                    petsc_reuse,   petsc_library_version};
