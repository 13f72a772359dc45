"""ASGI entry point for uvicorn/gunicorn: ``uvicorn gsr.service.asgi:app`` (keys and limits from GSR_SERVICE_*)."""

from gsr.service.app import create_app
from gsr.service.middleware import configure_logging
from gsr.service.settings import ServiceSettings

settings = ServiceSettings.from_env()
configure_logging(settings.log_json)
app = create_app(settings)
