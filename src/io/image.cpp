#include "io/image.h"
