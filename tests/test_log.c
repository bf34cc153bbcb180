/* Tests of the progress line: its text, the ETA from the simulated-time fraction, silence off a terminal. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/log.h"
#include "check.h"

static void test_format_fields(void)
{
    char buf[256];
    fs_progress_format(buf, sizeof buf, "wedge", 0.42, "t = 0.42, 17 fractures, 2000 elements", 12.4, 17.0);
    CHECK_MSG(!strcmp(buf, "wedge     42%  t = 0.42, 17 fractures, 2000 elements  0:12 elapsed, ETA 0:17"), "got '%s'",
              buf);
    fs_progress_format(buf, sizeof buf, "mesh", -1.0, "Delaunay triangulation", 65.0, -1.0);
    CHECK_MSG(!strcmp(buf, "mesh     Delaunay triangulation  1:05 elapsed"), "got '%s'", buf);
    /* a fraction without a rate yet: the ETA is shown as unknown */
    fs_progress_format(buf, sizeof buf, "springs", 0.0, "t = 0", 0.0, -1.0);
    CHECK_MSG(strstr(buf, "  0%") && strstr(buf, "ETA --:--"), "got '%s'", buf);
    /* hours, and fractions past 1 shown as 100 % */
    fs_progress_format(buf, sizeof buf, "wedge", 1.5, "x", 3725.0, 7322.0);
    CHECK_MSG(strstr(buf, "100%") && strstr(buf, "1:02:05 elapsed") && strstr(buf, "ETA 2:02:02"), "got '%s'", buf);
    /* a small buffer is cut, never overrun, and stays terminated */
    char small[12];
    memset(small, 'x', sizeof small);
    fs_progress_format(small, sizeof small, "wedge", 0.5, "a long detail that does not fit", 1.0, 1.0);
    CHECK(strlen(small) == sizeof small - 1);
}

static void test_eta(void)
{
    /* from 10 % to 30 % of the simulated time in 10 s: 20 % per 10 s, 70 % left -> 35 s */
    CHECK_NEAR(fs_progress_eta(10.0, 0.1, 0.3), 35.0, 1e-12);
    CHECK_NEAR(fs_progress_eta(5.0, 0.0, 1.0), 0.0, 1e-12);
    /* no advance yet (a cascade of fractures at one time): unknown, not infinite */
    CHECK(fs_progress_eta(10.0, 0.3, 0.3) < 0.0);
    CHECK(fs_progress_eta(10.0, 0.3, 0.301) < 0.0);
    CHECK(fs_progress_eta(-1.0, 0.0, 0.5) < 0.0);
}

static void test_silent_off_terminal(void)
{
    /* stderr into a file: not a terminal, so progress writes nothing, while log lines still go out */
    char path[] = "/tmp/fissure-test-log-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0)
        return;
    fflush(stderr);
    int saved = dup(STDERR_FILENO);
    dup2(fd, STDERR_FILENO);
    fs_progress("wedge", 0.5, "t = %.2f", 0.5);
    fs_progress_done();
    fs_info("a log line");
    fflush(stderr);
    dup2(saved, STDERR_FILENO);
    close(saved);
    FILE *f = fdopen(fd, "r");
    char text[256] = "";
    rewind(f);
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    unlink(path);
    CHECK_MSG(!strcmp(text, "fissure: a log line\n"), "stderr got '%s'", text);
}

/* JSON progress lines: the fields in order, null for an unknown fraction, fractions clamped,
 * quotes, backslashes and control characters escaped, and a message too long for the buffer cut
 * so that the line stays one valid object. */
static void test_json_line(void)
{
    char buf[512];
    fs_progress_json(buf, sizeof buf, "wedge", 0.25, "t = 0.25, 3 fractures", 1.5);
    CHECK_MSG(!strcmp(buf, "{\"phase\": \"wedge\", \"fraction\": 0.2500, \"message\": \"t = 0.25, 3 fractures\", "
                           "\"elapsed\": 1.500}"),
              "got %s", buf);
    fs_progress_json(buf, sizeof buf, "render", -1.0, "say \"hi\"\\\n\t", 0.0);
    CHECK_MSG(!strcmp(buf, "{\"phase\": \"render\", \"fraction\": null, \"message\": \"say \\\"hi\\\"\\\\\\n\\u0009\", "
                           "\"elapsed\": 0.000}"),
              "got %s", buf);
    fs_progress_json(buf, sizeof buf, "done", 1.7, "", 2.0);
    CHECK(strstr(buf, "\"fraction\": 1.0000") != NULL);
    char longer[2000];
    memset(longer, '"', sizeof longer - 1);
    longer[sizeof longer - 1] = '\0';
    fs_progress_json(buf, 200, "p", 0.5, longer, 3.0);
    size_t n = strlen(buf);
    CHECK(n < 200);
    CHECK_MSG(n > 20 && !strcmp(buf + n - 20, "\", \"elapsed\": 3.000}"), "got %s", buf);
    /* the message is cut between escapes, never inside one */
    const char *m = strstr(buf, "\"message\": \"") + 12;
    size_t quotes = 0;
    for (const char *p = m; *p && p < buf + n - 20; p += 2) {
        CHECK(p[0] == '\\' && p[1] == '"');
        quotes++;
    }
    CHECK(quotes > 10);
}

int main(void)
{
    RUN(test_format_fields);
    RUN(test_eta);
    RUN(test_silent_off_terminal);
    RUN(test_json_line);
    return check_finish();
}
