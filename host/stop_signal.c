/*
 * stop_signal.c — SIGINT and SIGTERM stop a render: the first within about a second,
 * writing what is finished; a second at once.
 */
#include "stop_signal.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

volatile sig_atomic_t stop_requested;
/* What the first stop prints, chosen before the handlers are installed (the handler
 * reads nothing else but the flag); NULL: nothing. */
static const char *stop_message;
static size_t stop_message_len;

/* The first SIGINT or SIGTERM stops the render within about a second and writes what
 * is finished (exit 6); a second one, of either kind, ends the process at once by the
 * signal's default action, writing nothing more. */
static void on_stop_signal(int sig)
{
    if (stop_requested) {
        signal(sig, SIG_DFL);
        raise(sig);   /* delivered as soon as this handler returns */
        return;
    }
    stop_requested = 1;
    if (!stop_message) return;
    ssize_t w = write(STDERR_FILENO, stop_message, stop_message_len);
    (void)w;
}

void install_signal_handlers(StopVoice voice)
{
    /* on a terminal the progress bar holds the line: start a fresh one */
    static const char msg[] = "\nclpt: stopping: writing what is finished (press Ctrl-C again to quit at once)\n";
    /* mpirun ends a job with SIGTERM to every rank also when one of them died */
    static const char mpi_msg[] = "\nclpt: stopping on SIGINT/SIGTERM (from you, or from mpirun because another MPI "
                                  "rank died; mpirun names it): writing what is finished\n";
    size_t skip = isatty(STDERR_FILENO) ? 0 : 1;
    stop_message = NULL;
    if (voice != STOP_QUIET) {
        stop_message = (voice == STOP_SAY_MPI ? mpi_msg : msg) + skip;
        stop_message_len = (voice == STOP_SAY_MPI ? sizeof mpi_msg - 1 : sizeof msg - 1) - skip;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

