/* The names in a directory, for `femcod report DIR` (Fortran has no portable way to
 * list one). femcod_list_directory(path, buf, cap): the names other than "." and "..",
 * each followed by a newline, into buf (at most cap bytes). Returns the bytes the whole
 * list needs (call again with a larger buffer when it exceeds cap), or -1 when the
 * directory cannot be opened (errno tells why). */
#include <dirent.h>
#include <string.h>

long femcod_list_directory(const char *path, char *buf, long cap)
{
    DIR *dir = opendir(path);
    struct dirent *entry;
    long used = 0;
    if (!dir) return -1;
    while ((entry = readdir(dir)) != NULL) {
        long n = (long) strlen(entry->d_name);
        if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0) continue;
        if (used + n + 1 <= cap) {
            memcpy(buf + used, entry->d_name, (size_t) n);
            buf[used + n] = '\n';
        }
        used += n + 1;
    }
    closedir(dir);
    return used;
}
