/* Logging and terminal progress. */
#include "base/log.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
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

/* The progress line's state: what is shown, when it was drawn, and where the ETA measures from. */
static struct {
    int tty;                 /* stderr is a terminal: -1 not checked yet, else 0 or 1 */
    double origin;           /* time of the first progress call (elapsed counts from it) */
    double last_draw;        /* time of the last redraw */
    char drawn_phase[32];    /* phase of the last redraw */
    char rate_phase[32];     /* fractional phase the ETA measures */
    double rate_t0, rate_f0; /* when that phase began and its fraction then */
    double scale;            /* fs_progress_scale, 0 meaning 1 */
} prog = {.tty = -1};

void fs_progress_scale(double scale) { prog.scale = scale; }

/* "M:SS", or "H:MM:SS" from an hour. */
static void clock_text(char *buf, size_t size, double seconds)
{
    long s = seconds > 0.0 ? (long)(seconds + 0.5) : 0;
    if (s >= 3600)
        snprintf(buf, size, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else
        snprintf(buf, size, "%ld:%02ld", s / 60, s % 60);
}

double fs_progress_eta(double seconds, double f0, double f)
{
    if (!(seconds >= 0.0) || !(f0 >= 0.0) || !(f <= 1.0) || !(f - f0 >= 0.005))
        return -1.0;
    return seconds * (1.0 - f) / (f - f0);
}

char *fs_progress_format(char *buf, size_t size, const char *phase, double fraction, const char *detail,
                         double elapsed, double eta)
{
    char pct[8] = "", el[24], left[32] = "";
    if (fraction >= 0.0)
        snprintf(pct, sizeof pct, "%3.0f%%  ", 100.0 * (fraction > 1.0 ? 1.0 : fraction));
    clock_text(el, sizeof el, elapsed);
    if (eta >= 0.0) {
        char e[24];
        clock_text(e, sizeof e, eta);
        snprintf(left, sizeof left, ", ETA %s", e);
    } else if (fraction >= 0.0) {
        snprintf(left, sizeof left, ", ETA --:--");
    }
    snprintf(buf, size, "%-8s %s%s  %s elapsed%s", phase, pct, detail, el, left);
    return buf;
}

static int terminal_columns(void)
{
    struct winsize ws;
    if (ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 20)
        return ws.ws_col;
    return 80;
}

static fs_progress_mode progress_mode = FS_PROGRESS_AUTO;

/* The JSON lines' state: when they count from, and the last one written. */
static struct {
    double origin;
    double last;
    char phase[32];
} json_prog;

void fs_progress_set_mode(fs_progress_mode mode)
{
    progress_mode = mode;
    json_prog.origin = fs_seconds();
    json_prog.last = -1.0;
    json_prog.phase[0] = '\0';
}

/* Appends s as a JSON string body (escaped) to buf at *n, stopping before a character that would
 * not fit with room for `reserve` more bytes. */
static void json_escape(char *buf, size_t size, size_t *n, const char *s, size_t reserve)
{
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        char esc[8];
        if (*p == '"' || *p == '\\')
            snprintf(esc, sizeof esc, "\\%c", *p);
        else if (*p == '\n')
            snprintf(esc, sizeof esc, "\\n");
        else if (*p < 0x20)
            snprintf(esc, sizeof esc, "\\u%04x", *p);
        else
            snprintf(esc, sizeof esc, "%c", *p);
        size_t len = strlen(esc);
        if (*n + len + reserve >= size)
            return;
        memcpy(buf + *n, esc, len);
        *n += len;
    }
}

char *fs_progress_json(char *buf, size_t size, const char *phase, double fraction, const char *message,
                       double elapsed)
{
    char tail[96], frac[16];
    if (fraction >= 0.0)
        snprintf(frac, sizeof frac, "%.4f", fraction > 1.0 ? 1.0 : fraction);
    else
        snprintf(frac, sizeof frac, "null");
    snprintf(tail, sizeof tail, "\", \"elapsed\": %.3f}", elapsed > 0.0 ? elapsed : 0.0);
    size_t n = 0;
    buf[0] = '\0';
    if (size < 128)
        return buf;
    n += (size_t)snprintf(buf, size, "{\"phase\": \"");
    json_escape(buf, size, &n, phase, 64 + strlen(tail));
    n += (size_t)snprintf(buf + n, size - n, "\", \"fraction\": %s, \"message\": \"", frac);
    json_escape(buf, size, &n, message, strlen(tail) + 1);
    snprintf(buf + n, size - n, "%s", tail);
    return buf;
}

static void json_line(const char *phase, double fraction, const char *message)
{
    char line[640];
    fs_progress_json(line, sizeof line, phase, fraction, message, fs_seconds() - json_prog.origin);
    fprintf(stderr, "%s\n", line);
    fflush(stderr);
}

void fs_progress_end(int ok, const char *message)
{
    fs_progress_done();
    if (progress_mode == FS_PROGRESS_JSON)
        json_line(ok ? "done" : "failed", ok ? 1.0 : -1.0, message ? message : "");
}

void fs_progress(const char *phase, double fraction, const char *fmt, ...)
{
    if (progress_mode == FS_PROGRESS_NONE)
        return;
    if (progress_mode == FS_PROGRESS_JSON) {
        double now = fs_seconds();
        if (fraction >= 0.0)
            fraction *= prog.scale > 0.0 ? prog.scale : 1.0;
        bool same = !strncmp(json_prog.phase, phase, sizeof json_prog.phase - 1);
        if (same && now - json_prog.last < 0.25 && !(fraction >= 1.0))
            return;
        char detail[400];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(detail, sizeof detail, fmt, ap);
        va_end(ap);
        json_line(phase, fraction, detail);
        json_prog.last = now;
        snprintf(json_prog.phase, sizeof json_prog.phase, "%s", phase);
        return;
    }
    if (log_level < FS_LOG_NORMAL)
        return;
    if (prog.tty < 0)
        prog.tty = isatty(STDERR_FILENO) ? 1 : 0;
    if (!prog.tty)
        return;
    double now = fs_seconds();
    if (prog.origin == 0.0)
        prog.origin = now;
    if (fraction >= 0.0) {
        fraction *= prog.scale > 0.0 ? prog.scale : 1.0;
        if (strncmp(prog.rate_phase, phase, sizeof prog.rate_phase - 1) || fraction < prog.rate_f0) {
            snprintf(prog.rate_phase, sizeof prog.rate_phase, "%s", phase);
            prog.rate_t0 = now;
            prog.rate_f0 = fraction;
        }
    }
    bool same_phase = !strncmp(prog.drawn_phase, phase, sizeof prog.drawn_phase - 1);
    if (progress_open && same_phase && now - prog.last_draw < 0.1)
        return;
    char detail[160], line[320];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(detail, sizeof detail, fmt, ap);
    va_end(ap);
    double eta = fraction >= 0.0 ? fs_progress_eta(now - prog.rate_t0, prog.rate_f0, fraction) : -1.0;
    fs_progress_format(line, sizeof line, phase, fraction, detail, now - prog.origin, eta);
    int columns = terminal_columns();
    if ((int)strlen(line) > columns - 1)
        line[columns - 1] = '\0';
    fprintf(stderr, "\r\033[K%s", line);
    fflush(stderr);
    progress_open = true;
    prog.last_draw = now;
    snprintf(prog.drawn_phase, sizeof prog.drawn_phase, "%s", phase);
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
