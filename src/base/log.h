/* Logging and progress on stderr; stdout is left to machine-readable output. */
#ifndef FS_BASE_LOG_H
#define FS_BASE_LOG_H

typedef enum { FS_LOG_QUIET = 0, FS_LOG_NORMAL = 1, FS_LOG_VERBOSE = 2 } fs_log_level;

void fs_log_set_level(fs_log_level level);
fs_log_level fs_log_get_level(void);

/* Informational message, shown unless quiet. */
void fs_info(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Detail shown only with --verbose. */
void fs_debug(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Warning, shown unless quiet. */
void fs_warn(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Progress line for a phase (rewritten in place) when stderr is a terminal and not quiet;
 * fraction in [0,1], or negative when unknown. fs_progress_done() ends the line. */
void fs_progress(const char *phase, double fraction, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void fs_progress_done(void);

/* Wall-clock seconds since an arbitrary origin (monotonic). */
double fs_seconds(void);

#endif
