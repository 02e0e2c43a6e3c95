"""``array_view``: an n-d view of part of a flat buffer, made without numba's reshape.

The compiled steps keep their scratch arrays in one flat float64 buffer (a single argument is
cheap to pass from Python) and carve their matrices from it on every call. numba's
``buffer[a:b].reshape(shape)`` goes through a generic C helper that re-derives the strides and
checks contiguity on every call (it showed in perf of the robot's step, eleven views per call).
``array_view`` builds the same view from the buffer's data pointer and stride directly (a few
integer operations). The view shares the buffer's memory and its reference count, as a slice
does.

It does not check bounds: ``start`` and ``shape`` must lie inside the buffer. Callers carve
compile-time layouts from buffers sized by those same layouts (``offsets_of``).
"""

from __future__ import annotations

from typing import Any

from numba import types
from numba.core import cgutils
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array


@intrinsic
def array_view(typingctx: Any, buffer: Any, start: Any, shape: Any) -> Any:
    """``buffer[start:start + prod(shape)].reshape(shape)`` for a 1-d ``buffer``, in nopython code.

    Args:
        buffer: 1-d array (any stride: a strided buffer gives a strided view).
        start: element index where the view begins (an integer).
        shape: tuple of integer extents, the view's shape (C order).

    Returns:
        The view (C-contiguous when the buffer is), sharing the buffer's memory.
    """
    del typingctx
    if not (isinstance(buffer, types.Array) and buffer.ndim == 1):
        return None
    if not isinstance(start, types.Integer):
        return None
    if not (isinstance(shape, types.BaseTuple) and len(shape) > 0
            and all(isinstance(t, types.Integer) for t in shape)):
        return None
    ndim = len(shape)
    layout = "C" if buffer.layout == "C" else "A"
    result = types.Array(buffer.dtype, ndim, layout)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        buffer_type, start_type, shape_type = signature.args
        buffer_value, start_value, shape_value = args
        source = make_array(buffer_type)(context, builder, buffer_value)
        view = make_array(signature.return_type)(context, builder)
        element_stride = builder.extract_value(source.strides, 0)
        offset = builder.mul(context.cast(builder, start_value, start_type, types.intp),
                             element_stride)
        data = builder.bitcast(
            builder.gep(builder.bitcast(source.data, cgutils.voidptr_t), [offset]),
            source.data.type)
        extents = [context.cast(builder, builder.extract_value(shape_value, i),
                                shape_type[i], types.intp) for i in range(ndim)]
        strides = [element_stride] * ndim
        for i in range(ndim - 2, -1, -1):
            strides[i] = builder.mul(strides[i + 1], extents[i + 1])
        populate_array(view, data=data, shape=cgutils.pack_array(builder, extents),
                       strides=cgutils.pack_array(builder, strides),
                       itemsize=source.itemsize, meminfo=source.meminfo, parent=source.parent)
        return impl_ret_borrowed(context, builder, signature.return_type, view._getvalue())

    return result(buffer, start, shape), codegen


__all__ = ["array_view"]
