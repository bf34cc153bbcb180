#include "geom/delaunay.h"
