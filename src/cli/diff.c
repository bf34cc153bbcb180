/* `fissure diff`: compares two images (PSNR, SSIM, largest difference) against thresholds. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "cli/cli.h"
#include "image/image.h"

static void print_diff_help(FILE *out)
{
    fputs("Usage: fissure diff [OPTION]... A B\n"
          "Compare two images of the same size and channel count (bit depths may differ).\n"
          "Prints 'psnr=... ssim=... max_diff=...' on stdout; exits 1 if over a threshold.\n"
          "\n"
          "  -p, --min-psnr DB       fail if the PSNR is below DB (default 40)\n"
          "  -S, --min-ssim S        fail if the SSIM is below S (default 0.98)\n"
          "  -m, --max-diff F        fail if any sample differs by more than F of the full range\n"
          "                          (default 1: no limit)\n"
          "  -h, --help              print this help and exit\n"
          "\n"
          "Exit status: 0 within the thresholds, 1 over, 64 usage error, 65 images not comparable,\n"
          "66 missing image.\n",
          out);
}

static bool parse_real(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

int fs_cli_diff(int argc, char **argv)
{
    static const struct option opts[] = {
        {"min-psnr", required_argument, NULL, 'p'},
        {"min-ssim", required_argument, NULL, 'S'},
        {"max-diff", required_argument, NULL, 'm'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    double min_psnr = 40, min_ssim = 0.98, max_diff = 1;
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "p:S:m:h", opts, NULL)) != -1) {
        switch (c) {
        case 'p':
            if (!parse_real(optarg, 0, 1000, &min_psnr)) {
                fprintf(stderr, "fissure diff: --min-psnr: expected decibels from 0 to 1000, got '%s'\n", optarg);
                return FS_ERR_USAGE;
            }
            break;
        case 'S':
            if (!parse_real(optarg, -1, 1, &min_ssim)) {
                fprintf(stderr, "fissure diff: --min-ssim: expected a number from -1 to 1, got '%s'\n", optarg);
                return FS_ERR_USAGE;
            }
            break;
        case 'm':
            if (!parse_real(optarg, 0, 1, &max_diff)) {
                fprintf(stderr, "fissure diff: --max-diff: expected a fraction from 0 to 1, got '%s'\n", optarg);
                return FS_ERR_USAGE;
            }
            break;
        case 'h': print_diff_help(stdout); return 0;
        default: fputs("Try 'fissure diff --help' for more information.\n", stderr); return FS_ERR_USAGE;
        }
    }
    if (argc - optind != 2) {
        fputs("fissure diff: expected two images A and B\nTry 'fissure diff --help' for more information.\n", stderr);
        return FS_ERR_USAGE;
    }
    fs_image a = {0}, b = {0};
    fs_image_diff d;
    if (fs_image_read(argv[optind], &a) < 0 || fs_image_read(argv[optind + 1], &b) < 0 ||
        fs_image_compare(&a, &b, &d) < 0) {
        fs_image_free(&a);
        fs_image_free(&b);
        fprintf(stderr, "fissure diff: %s\n", fs_error_message());
        return fs_error_domain() ? (int)fs_error_domain() : FS_ERR_INTERNAL;
    }
    fs_image_free(&a);
    fs_image_free(&b);
    bool over = d.psnr < min_psnr || d.ssim < min_ssim || d.max_diff > max_diff;
    printf("psnr=%.3f ssim=%.6f max_diff=%.6f %s\n", d.psnr, d.ssim, d.max_diff, over ? "FAIL" : "ok");
    if (over) {
        fprintf(stderr, "fissure diff: %s and %s differ beyond the thresholds (psnr >= %g, ssim >= %g, max_diff <= %g)\n",
                argv[optind], argv[optind + 1], min_psnr, min_ssim, max_diff);
        return 1;
    }
    return 0;
}
