"""The HTTP routes, one router per concern, each a thin layer over the plain functions of the shot contract
(`contract`)."""
