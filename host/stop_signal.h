/* stop_signal.h — the program's stop signals (SIGINT, SIGTERM): the first one raises
 * stop_requested, which the scheduler polls (ScheduleConfig.stop), and says why the
 * render stops; a second ends the process at once. */
#ifndef CLPT_STOP_SIGNAL_H
#define CLPT_STOP_SIGNAL_H

#include <signal.h>

/* Raised by the first SIGINT or SIGTERM: the one global the program keeps. */
extern volatile sig_atomic_t stop_requested;

/* Who says that the render stops. */
typedef enum {
    STOP_SAY,       /* one process */
    STOP_SAY_MPI,   /* rank 0 of an MPI job */
    STOP_QUIET      /* an MPI worker: rank 0 says it */
} StopVoice;

/* The first SIGINT or SIGTERM stops the render within about a second and writes what
 * is finished (exit 6); a second one, of either kind, ends the process at once by the
 * signal's default action, writing nothing more. */
void install_signal_handlers(StopVoice voice);

#endif /* CLPT_STOP_SIGNAL_H */
