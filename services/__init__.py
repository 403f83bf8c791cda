"""The navigation services and the transport they share."""
