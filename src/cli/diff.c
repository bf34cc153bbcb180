/* placeholder */ typedef int fs_placeholder_21569;
