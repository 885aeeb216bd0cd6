from typing import List, NamedTuple, Optional, Tuple, Union

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
    def lookup_tables(self) -> Tuple[cl.Buffer, Optional[cl.Buffer], Optional[cl.Buffer]]: ...

class KernelPrelude(NamedTuple):
    files: List[str]
    source: str
    build_options: str
    params: bytes

Option = Union[int, float, str]

def kernel_prelude(method: str = "esm", **options: Option) -> KernelPrelude: ...
def basis_shape(method: str, width: int, height: int, **options: Option) -> Tuple[int, int, int]: ...
def enqueue_transform(queue: cl.CommandQueue, width: int, height: int, depth: BufferLike, basis: BufferLike, *,
                      method: str = "esm", wait_for: Optional[List[cl.Event]] = None, **options: Option) -> cl.Event: ...
def enqueue_blur(queue: cl.CommandQueue, width: int, height: int, channels: int, src: BufferLike, dst: BufferLike, *,
                 tmp: Optional[BufferLike] = None, wait_for: Optional[List[cl.Event]] = None,
                 **options: Option) -> cl.Event: ...
def enqueue_reconstruct_points(queue: cl.CommandQueue, width: int, height: int, basis: BufferLike, u: BufferLike,
                               v: BufferLike, d: BufferLike, visibility: BufferLike, *, method: str = "esm",
                               count: Optional[int] = None, wait_for: Optional[List[cl.Event]] = None,
                               **options: Option) -> cl.Event: ...
def enqueue_reconstruct_grid(queue: cl.CommandQueue, width: int, height: int, basis: BufferLike, d: BufferLike,
                             visibility: BufferLike, *, method: str = "esm",
                             wait_for: Optional[List[cl.Event]] = None, **options: Option) -> cl.Event: ...
