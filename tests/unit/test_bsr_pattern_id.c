/* floor: core */
/* The sparsity-pattern id (bsr_update_pattern_id), which tells
 * factorisations and AMG setups when to redo their symbolic phase: the
 * same for the same pattern whatever the values and the thread count,
 * different when one column index (first or last block) or one row
 * length changes. */
#include <omp.h>
#include <stdint.h>

#include "core/bsr.h"
#include "tests/common/testutil.h"

static void fill(Bsr *A, int n, int per_row, double value)
{
    A->row_ptr[0] = 0;
    for (int i = 0; i < n; ++i) {
        A->row_ptr[i + 1] = A->row_ptr[i] + per_row;
        for (int k = 0; k < per_row; ++k) A->col[(int64_t)i * per_row + k] = (i + k) % n;
    }
    A->nnzb = (int64_t)n * per_row;
    for (int64_t e = 0; e < 9 * A->nnzb; ++e) A->val[e] = value;
}

int main(void)
{
    const int n = 10000, per_row = 30; /* 300,000 blocks */
    Bsr A = {0};
    CHECK(bsr_reserve(&A, n, (int64_t)n * per_row) == 0, "reserve");
    fill(&A, n, per_row, 1.0);
    omp_set_num_threads(1);
    bsr_update_pattern_id(&A);
    uint64_t id1 = A.pattern_id;
    omp_set_num_threads(2);
    bsr_update_pattern_id(&A);
    CHECK(A.pattern_id == id1, "thread count changes the id");
    fill(&A, n, per_row, -3.5);
    bsr_update_pattern_id(&A);
    CHECK(A.pattern_id == id1, "values change the id");
    const int64_t where[2] = {0, (int64_t)n * per_row - 1};
    for (int w = 0; w < 2; ++w) {
        fill(&A, n, per_row, 1.0);
        A.col[where[w]] = (A.col[where[w]] + 1) % n;
        bsr_update_pattern_id(&A);
        CHECK(A.pattern_id != id1, "column %lld changed, same id", (long long)where[w]);
    }
    fill(&A, n, per_row, 1.0);
    A.row_ptr[1] -= 1; /* row 0 one block shorter, row 1 one longer */
    bsr_update_pattern_id(&A);
    CHECK(A.pattern_id != id1, "row lengths changed, same id");
    bsr_free(&A);
    return test_summary("test_bsr_pattern_id");
}
