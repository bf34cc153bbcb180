#include "field/field.h"
