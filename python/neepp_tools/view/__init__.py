"""`neepp view SCENE.xml`: render a scene interactively in a local web page.

The page (served on 127.0.0.1 only, no network needed) shows the image converging; the mouse and keys move
the camera, each move restarting the image with a coarse first frame; the integrator's NEE++ options switch
live, the statistics of the current image (samples per pixel and per second, shadow rays traced, skipped
and occluded) follow it, and a button saves the image (EXR, PNG, statistics JSON) and NEE++'s map. NEE++'s visibility map
is kept across camera moves: it belongs to the scene, not to the view, and keeps learning from every view.
"""
