/* Minimal test harness for the C unit tests: checks count failures, main returns the status. */
#ifndef FS_TESTS_CHECK_H
#define FS_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_failures;
static int check_count;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        check_count++;                                                               \
        if (!(cond)) {                                                               \
            check_failures++;                                                        \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                            \
    } while (0)

#define CHECK_MSG(cond, ...)                                                         \
    do {                                                                             \
        check_count++;                                                               \
        if (!(cond)) {                                                               \
            check_failures++;                                                        \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                            \
            fputc('\n', stderr);                                                     \
        }                                                                            \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                  \
    do {                                                                                       \
        double check_a_ = (a), check_b_ = (b);                                                 \
        check_count++;                                                                         \
        if (!(fabs(check_a_ - check_b_) <= (tol))) {                                           \
            check_failures++;                                                                  \
            fprintf(stderr, "%s:%d: check failed: %s = %.17g, %s = %.17g, tolerance %g\n",     \
                    __FILE__, __LINE__, #a, check_a_, #b, check_b_, (double)(tol));            \
        }                                                                                      \
    } while (0)

/* Runs a test function and reports it. */
#define RUN(fn)                                                        \
    do {                                                               \
        int before_ = check_failures;                                  \
        fn();                                                          \
        printf("%s %s\n", check_failures == before_ ? "ok" : "FAIL", #fn); \
    } while (0)

static inline int check_finish(void)
{
    printf("%d checks, %d failed\n", check_count, check_failures);
    return check_failures ? 1 : 0;
}

#endif
