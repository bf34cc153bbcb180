/* Shared declarations of the command-line tool. */
#ifndef FS_CLI_CLI_H
#define FS_CLI_CLI_H

/* `fissure diff [OPTION]... A B`: argv[0] is "diff". Returns the exit status. */
int fs_cli_diff(int argc, char **argv);

#endif
