#include "io/output.h"
