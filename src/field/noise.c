#include "field/noise.h"
