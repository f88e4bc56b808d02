"""The heap of a run (ngfracture/run/heap.py): inside kept_heap freed blocks of 64 MB stay
in the process and serve the next ones without a page fault; on leaving, the free memory
goes back to the system."""
import resource

import numpy as np
import pytest

from ngfracture.run import heap

pytestmark = pytest.mark.skipif(heap._glibc() is None, reason="mallopt is glibc's")

SIZE = 8 * 2 ** 20       # doubles: 64 MB, above glibc's largest mmap threshold (32 MB)
BLOCK = SIZE * 8


def resident():
    """The resident set of this process, bytes."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize()


def faults_of_a_fresh_block():
    """Minor page faults of allocating and filling a 64 MB block after freeing one."""
    np.ones(SIZE)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    block = np.ones(SIZE)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    del block
    return faults


def test_freed_blocks_stay_inside_and_go_back_after():
    """Inside: four freed blocks stay resident, and a block after a freed one faults in no
    page (a handful for the interpreter's own objects). After: the resident set is back
    within half a block of where it was."""
    before = resident()
    with heap.kept_heap() as kept:
        assert kept
        blocks = [np.ones(SIZE) for _ in range(4)]
        del blocks
        kept_size = resident()
        inside = faults_of_a_fresh_block()
    after = resident()
    assert inside <= 8
    assert kept_size - before >= 3.5 * BLOCK
    assert after - before <= BLOCK / 2


def test_nested_runs_keep_the_heap_until_the_last_leaves():
    before = resident()
    with heap.kept_heap():
        with heap.kept_heap():
            pass
        blocks = [np.ones(SIZE) for _ in range(4)]
        del blocks
        assert resident() - before >= 3.5 * BLOCK
    assert heap._runs == 0 and resident() - before <= BLOCK / 2
