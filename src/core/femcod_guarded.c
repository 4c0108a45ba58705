/* Run a probe in a child process, so that a library crashing or looping on a corrupt
 * input file (libhdf5 1.10 reads a variable-length string's global-heap entry with the
 * length the file gives: a corrupt length is a memmove past the heap, or minutes of work)
 * takes down only the child. femcod_hdf5's h5_open probes every HDF5 file it reads this
 * way before reading it itself.
 *
 * femcod_guarded(probe, arg, seconds): fork; the child runs probe(arg) under an alarm of
 * `seconds` and leaves with _exit (0: the probe succeeded). Returns 0 when the child
 * ended well, 1 when it failed or was killed by a signal, 2 when the alarm stopped it,
 * -1 when no child could be made, or under MPI (OMPI_COMM_WORLD_SIZE, PMI_RANK or
 * PMIX_RANK set: a rank must not fork), and the caller then reads without the guard. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

int femcod_guarded(int (*probe)(void *), void *arg, int seconds)
{
    pid_t pid;
    int status = 0;
    if (getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_RANK") || getenv("PMIX_RANK")) return -1;
    pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        /* Nothing of the parent's output buffers may be flushed twice: _exit only. A crash
         * is the parent's to report: the runtime's backtrace handlers are reset and
         * standard error goes to /dev/null. */
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) dup2(null, 2);
        signal(SIGSEGV, SIG_DFL);
        signal(SIGBUS, SIG_DFL);
        signal(SIGFPE, SIG_DFL);
        signal(SIGILL, SIG_DFL);
        signal(SIGABRT, SIG_DFL);
        signal(SIGALRM, SIG_DFL);
        alarm((unsigned) seconds);
        _exit(probe(arg) == 0 ? 0 : 1);
    }
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) return -1;
    }
    if (WIFEXITED(status)) return WEXITSTATUS(status) == 0 ? 0 : 1;
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) return 2;
    return 1;
}
