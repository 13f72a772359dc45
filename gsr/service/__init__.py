"""The HTTP reasoning service (FastAPI): ``create_app`` and its limits; run it with ``gsr serve``."""

from gsr.service.settings import ServiceSettings


def create_app(settings: ServiceSettings | None = None):
    """The FastAPI application (imports FastAPI on first use)."""
    from gsr.service.app import create_app as _create

    return _create(settings)


__all__ = ["ServiceSettings", "create_app"]
