#include "io/sidecar.h"
