/* Tests: a model's setup from a whole run's configuration, as sim makes it (without maps). */
#ifndef FS_TESTS_SETUP_H
#define FS_TESTS_SETUP_H

#include "sim/settings.h"

/* A pointer to the fs_model_setup of cfg, valid until the end of the enclosing block. */
#define SETUP(cfg) ((const fs_model_setup *)(fs_model_setup[]){fs_config_model_setup(cfg)})

#endif
