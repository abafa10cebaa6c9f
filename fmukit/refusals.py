"""How an FMU refuses a call: ``Refused``, with a message that names the cause."""
from __future__ import annotations


class Refused(ValueError):
    """A call the FMU refuses; the host gets a failed status, and this message."""


def explain(error: BaseException) -> str:
    """What went wrong, for the user: a refusal's own message, or the exception's type and
    message."""
    return str(error) if isinstance(error, Refused) else f"{type(error).__name__}: {error}"


def naming(instance_name: str, text: str) -> str:
    """A message as it leaves the FMU: naming the FMU, for hosts whose logs do not
    (libcosim's log shows neither the instance nor the call)."""
    return f"{instance_name}: {text}"


def unnamed(instance_name: str, message: str) -> str:
    """A message without the FMU's name in front, for a host that shows the name itself."""
    prefix = f"{instance_name}: "
    return message[len(prefix):] if message.startswith(prefix) else message
