"""MathJax 3 served from the built site, so equations render without a network.

Wraps the ``sphinx-mathjax-offline`` package (docs extra), which copies its MathJax
files into ``_static/mathjax`` once the build has finished and points ``mathjax_path``
there. That package does not declare whether it is safe for parallel builds; it is:
its only work is that copy, after every worker has finished.
"""

import importlib


def setup(app):
    importlib.import_module("sphinx-mathjax-offline").setup(app)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
