from typing import Any, Iterable, List, Optional, Sequence, Union

from distributed import Client, Future, WorkerPlugin

class DevicePlugin(WorkerPlugin):
    name: str
    selector: str
    def __init__(self, selector: str = "") -> None: ...

def filter_frames(client: Client, frames: Iterable[Any], *, method: str = "esm", device: str = "",
                  outputs: Optional[Sequence[Any]] = None, **options: Union[int, float, str]) -> List[Future]: ...
