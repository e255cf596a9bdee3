"""The registration view: two surfaces, their spherical maps and the map between them,
stage by stage (:func:`.view.show_registration`)."""
