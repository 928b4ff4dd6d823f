"""The Relief Snake benchmark (make bench): run_bench (the suite, sweeps and speed) and random_suite
(the randomized suite of issue 14). Modules: cases, run, score, report, plots."""
