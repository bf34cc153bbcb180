/* libFuzzer harness of the preset parser (make fuzz): the bytes up to the first NUL are a preset,
 * the bytes after it a --set assignment. Whatever they are, parsing, the override and the checks
 * must end cleanly (no crash, no sanitizer report); a configuration that passes them must dump to
 * INI that parses back, and dump again to the same text. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "io/preset.h"

/* The dump as a string (malloc'd). */
static char *dump(const fs_config *cfg)
{
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    if (!f)
        abort();
    fs_preset_dump(cfg, f);
    fclose(f);
    return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
    size_t preset_len = strlen(text);
    const char *assignment = preset_len < size ? text + preset_len + 1 : NULL;

    fs_config cfg = fs_config_default();
    fs_error_clear();
    int ok = fs_preset_load_string(text, "fuzz.ini", &cfg) == 0;
    if (!ok && fs_error_domain() != FS_ERR_DATA) {
        fprintf(stderr, "a bad preset must be FS_ERR_DATA, got %d: %s\n", (int)fs_error_domain(), fs_error_message());
        abort();
    }
    if (ok && assignment && *assignment)
        ok = fs_preset_set(&cfg, assignment) == 0;
    if (ok)
        ok = fs_preset_validate(&cfg, "fuzz.ini") == 0;
    if (ok) {
        char *first = dump(&cfg);
        fs_config back = fs_config_default();
        if (fs_preset_load_string(first, "dump", &back) != 0) {
            fprintf(stderr, "the dump does not parse back: %s\n--- dump:\n%s", fs_error_message(), first);
            abort();
        }
        char *second = dump(&back);
        if (strcmp(first, second) != 0) {
            fprintf(stderr, "dump -> parse -> dump changed the text\n--- first:\n%s--- second:\n%s", first, second);
            abort();
        }
        free(first);
        free(second);
    }
    free(text);
    return 0;
}
