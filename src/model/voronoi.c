#include "model/voronoi.h"
