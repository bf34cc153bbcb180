#include "io/preset.h"
