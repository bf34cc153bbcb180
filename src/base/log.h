/* Logging and progress on stderr; stdout is left to machine-readable output. */
#ifndef FS_BASE_LOG_H
#define FS_BASE_LOG_H

#include <stddef.h>

typedef enum { FS_LOG_QUIET = 0, FS_LOG_NORMAL = 1, FS_LOG_VERBOSE = 2 } fs_log_level;

void fs_log_set_level(fs_log_level level);
fs_log_level fs_log_get_level(void);

/* Informational message, shown unless quiet. */
void fs_info(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Detail shown only with --verbose. */
void fs_debug(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Warning, shown unless quiet. */
void fs_warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Progress line for a phase (rewritten in place with \r) when stderr is a terminal and not quiet;
 * fraction in [0,1] (simulated time / end), or negative when unknown. The line shows the phase,
 * the percentage, the detail, the time elapsed since the first progress line and the ETA; it is
 * redrawn at most 10 times a second (at once when the phase changes) and cut to the terminal's
 * width. fs_progress_done() clears it; log lines clear it first and it comes back on the next call.
 * design: the ETA extrapolates the rate of the fraction since the phase began (a fractional phase
 * begins when its name changes or its fraction goes back), so it follows simulated time, not the
 * number of events, which bunch up as cracks cascade. */
void fs_progress(const char *phase, double fraction, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void fs_progress_done(void);

/* Multiplies the fractions given to fs_progress from now on by scale (1 at start): a model that runs
 * a segment [.., t_k] of a run to `end` reports time / t_k, shown as time / end with scale t_k / end. */
void fs_progress_scale(double scale);

/* The progress line's text, without escape codes, into buf (size bytes, always terminated):
 * "PHASE  NN%  DETAIL  M:SS elapsed, ETA M:SS"; the percentage only for fraction >= 0, the ETA
 * only for eta >= 0 ("ETA --:--" when a fraction is known but eta is not). Returns buf. */
char *fs_progress_format(char *buf, size_t size, const char *phase, double fraction, const char *detail,
                         double elapsed, double eta);

/* Seconds left at a constant rate: the fraction went from f0 to f in `seconds`; negative (unknown)
 * when it has not advanced by at least 0.5 % or the inputs are out of range. */
double fs_progress_eta(double seconds, double f0, double f);

/* How progress is reported (--progress). */
typedef enum {
    FS_PROGRESS_AUTO = 0, /* the line above, when stderr is a terminal and not quiet */
    FS_PROGRESS_JSON,     /* machine-readable lines on stderr, whatever stderr is, even when quiet */
    FS_PROGRESS_NONE      /* nothing */
} fs_progress_mode;

/* Sets the mode (AUTO at start); elapsed times count from this call. In JSON mode every
 * fs_progress call writes one line holding one JSON object (fs_progress_json), except that within
 * one phase lines come at most 4 times a second (a change of phase, or a fraction reaching 1, is
 * always written). */
void fs_progress_set_mode(fs_progress_mode mode);

/* Ends the progress of a run: clears the terminal line, and in JSON mode writes the last line:
 * phase "done" with fraction 1 when ok, else phase "failed" with fraction null; message is its
 * detail (the error for a failure). */
void fs_progress_end(int ok, const char *message);

/* One JSON progress line, without the newline, into buf (size bytes; a message that does not fit
 * is cut, keeping the line valid JSON):
 *   {"phase": "PHASE", "fraction": F, "message": "DETAIL", "elapsed": S}
 * F in [0, 1] with 4 decimals, or null when negative (unknown); S in seconds with 3 decimals.
 * Returns buf. */
char *fs_progress_json(char *buf, size_t size, const char *phase, double fraction, const char *message,
                       double elapsed);

/* Wall-clock seconds since an arbitrary origin (monotonic). */
double fs_seconds(void);

#endif
