"""The MIT Push Dataset objects, limit-surface parameter from shape, and contact annotation."""

from pushjax.geometry.contact import NO_CONTACT_FRACTION, ContactAnnotation, annotate
from pushjax.geometry.objects import (
    OBJECT_NAMES,
    PUSHER_RADIUS,
    THICKNESS,
    PushObject,
    all_objects,
    footprint_grid,
    get_object,
    limit_surface_ratio,
    support,
    support_cells,
    support_feet,
)
