# Plain pytest collects only the bpy-free tests here; the rest run inside Blender via run_tests.py.
collect_ignore = ["test_addon.py", "test_extraction.py", "run_tests.py", "bench_operator.py", "ui"]
