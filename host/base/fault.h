/*
 * fault.h — test-only fault injection, through environment variables.
 *
 * Each variable makes one real code path fail the way the world outside can make it
 * fail, so that the tests can check clpt's handling and exit codes by running the
 * program itself (tests/test_exit_codes.c, tests/test_device_errors.c). They are for
 * tests only: not part of the interface, and never set in normal use.
 *
 *   CLPT_TEST_FAIL_ALLOC=film      the host film's allocation fails as if memory ran
 *                                  out: an internal error, exit 1
 *   CLPT_TEST_DEVICE_MEMORY=I:BYTES[,I:BYTES...]
 *                                  OpenCL device I (its --list-devices index) reports
 *                                  at most BYTES of global memory and of largest
 *                                  allocation, as a small GPU would
 *   CLPT_TEST_BUILD_FAIL=I[,I...]  OpenCL device I builds the kernels with an extra
 *                                  option that breaks them (-D__kernel=<unknown type>):
 *                                  a real compile failure, with a build log
 *   CLPT_TEST_FAIL=D:B[,D:B...]    the device at position D of the render's selection
 *                                  fails when it starts its B-th batch (from 0), as a
 *                                  real fault would: its batches go back to the queue
 *
 * docs/hardening.md lists them too.
 */
#ifndef CLPT_FAULT_H
#define CLPT_FAULT_H

#include <stddef.h>
#include <stdint.h>

/* 1 when CLPT_TEST_FAIL_ALLOC names `site`. */
int fault_alloc_fails(const char *site);

/* Lowers *global_mem and *max_alloc to the CLPT_TEST_DEVICE_MEMORY cap of device
 * `index`, if it has one. */
void fault_device_memory(unsigned index, uint64_t *global_mem, uint64_t *max_alloc);

/* The extra build options that make device `index`'s build fail when
 * CLPT_TEST_BUILD_FAIL names it; NULL otherwise. */
const char *fault_build_options(unsigned index);

/* The batch (counted from 0) at which the device at position `device_index` of the
 * selection is to fail, from CLPT_TEST_FAIL; -1: never. */
long fault_device_batch(size_t device_index);

#endif /* CLPT_FAULT_H */
