"""ASGI entry point for uvicorn/gunicorn: ``uvicorn gsr.service.asgi:app`` (limits from GSR_SERVICE_*)."""

from gsr.service.app import create_app
from gsr.service.settings import ServiceSettings

app = create_app(ServiceSettings.from_env())
