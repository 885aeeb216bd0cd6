from typing import List, Optional, Union

import pyopencl as cl
import pyopencl.array as cla

BufferLike = Union[cl.Buffer, cla.Array]

class Pipeline:
    queue: cl.CommandQueue
    width: int
    height: int
    def __init__(self, queue: cl.CommandQueue, width: int, height: int, method: str = "esm",
                 **options: Union[int, float, str]) -> None: ...
    @property
    def device_bytes(self) -> int: ...
    def prefilter(self, depth: BufferLike, wait_for: Optional[List[cl.Event]] = None) -> cl.Event: ...
    def reconstruct(self, u: BufferLike, v: BufferLike, d: BufferLike, visibility: BufferLike, *,
                    count: Optional[int] = None, f: Optional[BufferLike] = None, row: int = 0,
                    wait_for: Optional[List[cl.Event]] = None) -> cl.Event: ...
    def reconstruct_grid(self, d: BufferLike, visibility: BufferLike,
                         wait_for: Optional[List[cl.Event]] = None) -> cl.Event: ...
