#include "geom/sample.h"
