import os
import tempfile

# Tests must not touch the user's automaton cache: one fresh directory per test session.
os.environ.setdefault("CRAFTSUITE_CACHE_DIR", tempfile.mkdtemp(prefix="craftsuite-test-cache-"))
