/* Logging and terminal progress. */
#include "base/log.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

static fs_log_level log_level = FS_LOG_NORMAL;
static bool progress_open;

void fs_log_set_level(fs_log_level level) { log_level = level; }
fs_log_level fs_log_get_level(void) { return log_level; }

static void vlog(const char *prefix, const char *fmt, va_list ap)
{
    if (progress_open)
        fs_progress_done();
    fputs(prefix, stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

void fs_info(const char *fmt, ...)
{
    if (log_level < FS_LOG_NORMAL)
        return;
    va_list ap;
    va_start(ap, fmt);
    vlog("fissure: ", fmt, ap);
    va_end(ap);
}

void fs_debug(const char *fmt, ...)
{
    if (log_level < FS_LOG_VERBOSE)
        return;
    va_list ap;
    va_start(ap, fmt);
    vlog("fissure: ", fmt, ap);
    va_end(ap);
}

void fs_warn(const char *fmt, ...)
{
    if (log_level < FS_LOG_NORMAL)
        return;
    va_list ap;
    va_start(ap, fmt);
    vlog("fissure: warning: ", fmt, ap);
    va_end(ap);
}

void fs_progress(const char *phase, double fraction, const char *fmt, ...)
{
    if (log_level < FS_LOG_NORMAL || !isatty(STDERR_FILENO))
        return;
    char detail[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    if (fraction >= 0)
        fprintf(stderr, "\r\033[K%-10s %3.0f%%  %s", phase, 100.0 * (fraction > 1 ? 1 : fraction), detail);
    else
        fprintf(stderr, "\r\033[K%-10s %s", phase, detail);
    fflush(stderr);
    progress_open = true;
}

void fs_progress_done(void)
{
    if (progress_open) {
        fputs("\r\033[K", stderr);
        fflush(stderr);
        progress_open = false;
    }
}

double fs_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
