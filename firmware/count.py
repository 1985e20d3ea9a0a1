"""Counts the instructions of one call of each firmware update function by
single-stepping it under QEMU's gdb stub: the exact figure the SysTick
measurement in `src/main.rs` estimates. Run by `scripts/firmware` as

    gdb-multiarch -batch -x count.py ELF

with QEMU waiting on MSP_COUNT_PORT and MSP_COUNT_SYMBOLS naming a file of
"<hex address> <name>" lines. Prints "count: <name> <instructions>" for the
calls numbered in AT (the same path for every call after the first few).
"""

import os

import gdb  # type: ignore[import-not-found]

AT = (60, 61)
# the adaptive update's path varies: still (calls 60, 61: nothing has moved
# the input past the gate) and learning, every candidate's estimator
# updated: 200 samples after the set point's step at 5000 and 433 after the
# load's at 6667 (by 1500 the first response has settled and the gate is
# shut: that call is a still one)
AT_OF = {"adaptive_step": (60, 61, 5200, 7100)}


def pc() -> int:
    return int(gdb.parse_and_eval("$pc")) & ~1


def main() -> None:
    gdb.execute("set pagination off")
    gdb.execute("set confirm off")
    gdb.execute("target remote 127.0.0.1:%s" % os.environ.get("MSP_COUNT_PORT", "1234"))
    names = {}
    with open(os.environ["MSP_COUNT_SYMBOLS"]) as f:
        for line in f:
            address, name = line.split()
            names[int(address, 16) & ~1] = name
    breakpoints = {
        name: gdb.Breakpoint("*0x%x" % address, internal=True)
        for address, name in names.items()
    }
    calls: dict = {}
    while True:
        try:
            gdb.execute("continue", to_string=True)
        except gdb.error:
            break
        name = names.get(pc())
        if name is None:
            break
        calls[name] = calls.get(name, 0) + 1
        at = AT_OF.get(name, AT)
        if calls[name] not in at:
            continue
        ret = int(gdb.parse_and_eval("$lr")) & ~1
        steps = 0
        while pc() != ret:
            gdb.execute("stepi", to_string=True)
            steps += 1
        print("count: %s %d" % (name, steps), flush=True)
        if calls[name] == at[-1]:
            breakpoints.pop(name).delete()
            if not breakpoints:
                break
    gdb.execute("kill")


main()
