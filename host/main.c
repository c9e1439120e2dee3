/* main.c — command line → render → exit code. */
#include <stdio.h>

#include "status.h"

int main(void)
{
    fprintf(stderr, "clpt: not built yet\n");
    return ST_INTERNAL;
}
