"""The API's routes, each module an ``APIRouter`` that ``create_app`` includes: the computing
endpoints, the dashboard's page and sessions, and the atlas jobs (the API's and a session's)."""
