/* ARM semihosting (bkpt 0xAB): console output and exit, no libc needed. */
#ifndef SEMIHOST_H
#define SEMIHOST_H

#ifdef GYROCAL_HOST
/* The same example built for the host, to compare its float32 results bit for bit. */
#include <stdio.h>
#include <stdlib.h>
static inline void sh_puts(const char *s)
{
    fputs(s, stdout);
}
static inline void sh_exit(int code)
{
    exit(code);
}
#else

static inline int sh_call(int op, const void *arg)
{
    register int r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static inline void sh_puts(const char *s)
{
    sh_call(0x04, s); /* SYS_WRITE0 */
}

__attribute__((noreturn)) static inline void sh_exit(int code)
{
    /* SYS_EXIT: ADP_Stopped_ApplicationExit gives QEMU exit status 0, RunTimeErrorUnknown status 1. */
    sh_call(0x18, (const void *)(code == 0 ? 0x20026 : 0x20023));
    for (;;) {
    }
}

#endif /* GYROCAL_HOST */
#endif
