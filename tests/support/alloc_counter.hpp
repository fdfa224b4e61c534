#pragma once
// Number of heap allocations (malloc, calloc, realloc, memalign, ...) so far in this test
// executable; link tests/support/alloc_counter.cpp to use it.
long omnivert_test_allocations();
