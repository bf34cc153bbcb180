/* libFuzzer harness of the grey-level map loader (make fuzz): the bytes are an image file. Whatever
 * they are, the header check and the decoder must end cleanly (no crash, no sanitizer report), a
 * refused image must come with FS_ERR_DATA, and an accepted one must have the size its header
 * declares, within the map limit. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "base/error.h"
#include "image/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int w = 0, h = 0;
    float *grey = NULL;
    fs_error_clear();
    if (fs_image_decode_grey(data, size, "fuzz", &w, &h, &grey) != 0) {
        if (fs_error_domain() != FS_ERR_DATA || grey) {
            fprintf(stderr, "a refused image must be FS_ERR_DATA without pixels, got %d: %s\n",
                    (int)fs_error_domain(), fs_error_message());
            abort();
        }
        return 0;
    }
    fs_image_header header;
    if (fs_image_probe(data, size, &header) != 0 || header.width != w || header.height != h ||
        (int64_t)w * h > FS_IMAGE_MAX_MAP_PIXELS) {
        fprintf(stderr, "decoded %d x %d, the header says %lld x %lld\n", w, h, (long long)header.width,
                (long long)header.height);
        abort();
    }
    free(grey);
    return 0;
}
