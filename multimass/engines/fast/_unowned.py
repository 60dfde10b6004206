"""`unowned`: an array without its owner, so that numba counts no references to it.

numba counts references to an array's owner (its meminfo) with an atomic add each time
the array is passed to a function, bound to a new name (as an inlined function's
arguments are) or a view of it is taken, and again when that name dies; LLVM does not
prune them. In a kernel's step loop these counts are a large share of the time: in the
rigid block's segment (`._block_segment`), ten atomic adds per right-hand side (its
arguments y, out, mp, par and samples), a third of the time. For an array without an
owner — as a module constant is — the count is a test of a null pointer.

Only for arrays whose owner outlives every use of the view: a kernel's own arguments,
within the call (the caller holds them). A view is never returned, stored or boxed.
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["unowned"]


@intrinsic
def unowned(typingctx, array):
    """`array` without its owner: the same data, shape and strides, no reference count.

    The view's meminfo and parent are null pointers; see the module docstring for when
    it is safe.
    """
    if not isinstance(array, types.Array):
        return None

    def codegen(context, builder, sig, args):
        view = context.make_array(sig.return_type)(context, builder, value=args[0])
        view.meminfo = cgutils.get_null_value(view.meminfo.type)
        view.parent = cgutils.get_null_value(view.parent.type)
        return view._getvalue()

    return array(array), codegen
