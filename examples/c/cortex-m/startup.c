/*
 * Start-up for the C example on a Cortex-M4F (QEMU mps2-an386): the vector
 * table, the FPU switched on, .bss cleared, then newlib's semihosting start
 * (rdimon: printf goes to the host's terminal), main, and an exit QEMU ends on.
 */
#include <stdint.h>

extern int main(void);
extern void _start(void); /* newlib's crt0 (rdimon.specs): stack, heap, main, exit */
extern uint32_t __stack_top;

void reset_handler(void) {
    /* CPACR: full access to CP10 and CP11 (the FPU) before any float instruction */
    *(volatile uint32_t *)0xE000ED88 |= (0xFu << 20);
    __asm volatile("dsb\n isb");
    _start();
    for (;;) {
    }
}

static void fault_handler(void) {
    for (;;) {
    }
}

__attribute__((section(".vectors"), used)) static const void *vectors[16] = {
    &__stack_top, (void *)reset_handler, (void *)fault_handler, (void *)fault_handler,
    (void *)fault_handler, (void *)fault_handler, (void *)fault_handler, 0, 0, 0, 0,
    (void *)fault_handler, (void *)fault_handler, 0, (void *)fault_handler,
    (void *)fault_handler,
};
