/* placeholder */ typedef int fs_placeholder_15351;
