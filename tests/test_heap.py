"""The heap of a run (ngfracture/run/heap.py): inside kept_heap a freed block of 64 MB
serves the next one without a page fault; after it, a new block is fresh memory again."""
import resource

import numpy as np
import pytest

from ngfracture.run import heap

pytestmark = pytest.mark.skipif(heap._glibc() is None, reason="mallopt is glibc's")

SIZE = 8 * 2 ** 20       # doubles: 64 MB, above glibc's mmap threshold


def faults_of_a_fresh_block():
    """Minor page faults of allocating and filling a 64 MB block after freeing one."""
    np.ones(SIZE)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    block = np.ones(SIZE)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    del block
    return faults


def test_a_freed_block_serves_the_next_inside_and_is_returned_after():
    """Inside: the memory of the freed block is reused, no page is faulted in (a handful
    for the interpreter's own objects). After: glibc maps a new block, at least one fault
    per 2 MB huge page of it."""
    with heap.kept_heap() as kept:
        assert kept
        faults_of_a_fresh_block()
        inside = faults_of_a_fresh_block()
    after = faults_of_a_fresh_block()
    assert inside <= 8
    assert after >= SIZE * 8 // (2 * 2 ** 20)


def test_nested_runs_keep_the_heap_until_the_last_leaves():
    with heap.kept_heap():
        with heap.kept_heap():
            pass
        faults_of_a_fresh_block()
        assert faults_of_a_fresh_block() <= 8
    assert heap._runs == 0
