"""The API's routes: one module per resource, each an ``APIRouter`` that ``create_app`` includes."""
