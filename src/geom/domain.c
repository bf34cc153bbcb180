#include "geom/domain.h"
