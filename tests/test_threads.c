/* Tests of the parallel loop: every item runs once, and results reduced in index order are the same
 * bit for bit at 1, 2, 3 and 4 threads; the static partition covers a range in contiguous parts. */
#include <stdint.h>
#include <string.h>

#include "base/rng.h"
#include "base/threads.h"
#include "check.h"

enum { ITEMS = 203, LEN = 5000 };

typedef struct {
    const double *data;  /* LEN values */
    int32_t parts;
    double *partial;     /* per part: its sum, added up in index order within the part */
    int32_t *runs;       /* per part: how often it ran */
} sum_job;

/* Part p of the data summed sequentially, with uneven work (later parts repeat their sum). */
static void sum_part(void *ctx, int32_t p)
{
    sum_job *job = ctx;
    int32_t i0, i1;
    fs_parallel_part(LEN, job->parts, p, &i0, &i1);
    double s = 0.0;
    for (int rep = 0; rep <= p % 7; rep++) {
        s = 0.0;
        for (int32_t i = i0; i < i1; i++)
            s += job->data[i] * job->data[i] / (1.0 + job->data[i]);
    }
    job->partial[p] = s;
    job->runs[p]++;
}

/* The reduction of the parts, in index order. */
static double run_sum(const double *data, int threads, int32_t *runs)
{
    double partial[ITEMS];
    sum_job job = {data, ITEMS, partial, runs};
    memset(runs, 0, ITEMS * sizeof *runs);
    fs_parallel_for(ITEMS, threads, sum_part, &job);
    double total = 0.0;
    for (int32_t p = 0; p < ITEMS; p++)
        total += partial[p];
    return total;
}

static void test_parallel_for_deterministic(void)
{
    static double data[LEN];
    for (int32_t i = 0; i < LEN; i++)
        data[i] = fs_rand01(11, FS_RNG_TEST, (uint64_t)i) * 1e3 - 1e2;
    int32_t runs[ITEMS];
    double one = run_sum(data, 1, runs);
    for (int threads = 1; threads <= 4; threads++)
        for (int trial = 0; trial < 5; trial++) {
            double total = run_sum(data, threads, runs);
            CHECK_MSG(memcmp(&total, &one, sizeof total) == 0, "%d threads: %.17g != %.17g", threads, total, one);
            int32_t wrong = 0;
            for (int32_t p = 0; p < ITEMS; p++)
                wrong += runs[p] != 1;
            CHECK_MSG(wrong == 0, "%d threads: %d items not run exactly once", threads, wrong);
        }
    /* the budget (threads <= 0) and more threads than items */
    double total = run_sum(data, 0, runs);
    CHECK(memcmp(&total, &one, sizeof total) == 0);
    int32_t few_runs[ITEMS];
    double few[3];
    sum_job job = {data, ITEMS, few, few_runs};
    memset(few_runs, 0, sizeof few_runs);
    fs_parallel_for(3, 16, sum_part, &job);
    CHECK(few_runs[0] == 1 && few_runs[1] == 1 && few_runs[2] == 1 && few_runs[3] == 0);
    fs_parallel_for(0, 4, sum_part, &job); /* nothing to do */
    CHECK(few_runs[0] == 1);
}

/* The parts tile [0, n) in order, with sizes differing by at most one. */
static void test_parallel_part(void)
{
    const int32_t ns[] = {0, 1, 7, 100, 1001};
    for (int q = 0; q < 5; q++)
        for (int parts = 1; parts <= 9; parts++) {
            int32_t expect = 0, smallest = ns[q], largest = 0;
            for (int p = 0; p < parts; p++) {
                int32_t i0, i1;
                fs_parallel_part(ns[q], parts, p, &i0, &i1);
                CHECK(i0 == expect && i1 >= i0);
                expect = i1;
                smallest = i1 - i0 < smallest ? i1 - i0 : smallest;
                largest = i1 - i0 > largest ? i1 - i0 : largest;
            }
            CHECK(expect == ns[q]);
            CHECK(largest - smallest <= 1);
        }
}

int main(void)
{
    RUN(test_parallel_for_deterministic);
    RUN(test_parallel_part);
    return check_finish();
}
