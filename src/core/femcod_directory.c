/* The names in a directory, for `femcod report DIR` (Fortran has no portable way to
 * list one). femcod_list_directory(path, buf, cap): the names other than "." and "..",
 * sorted by byte value, each followed by a newline, into buf (at most cap bytes).
 * Returns the bytes the whole list needs (call again with a larger buffer when it
 * exceeds cap), or -1 when the directory cannot be read (errno tells why). */
#include <dirent.h>
#include <stdlib.h>
#include <string.h>

static int not_dots(const struct dirent *e)
{
    return strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
}

static int by_bytes(const struct dirent **a, const struct dirent **b)
{
    return strcmp((*a)->d_name, (*b)->d_name);
}

long femcod_list_directory(const char *path, char *buf, long cap)
{
    struct dirent **list;
    long used = 0;
    int n = scandir(path, &list, not_dots, by_bytes);
    if (n < 0) return -1;
    for (int k = 0; k < n; k++) {
        long len = (long) strlen(list[k]->d_name);
        if (used + len + 1 <= cap) {
            memcpy(buf + used, list[k]->d_name, (size_t) len);
            buf[used + len] = '\n';
        }
        used += len + 1;
        free(list[k]);
    }
    free(list);
    return used;
}
