"""vtk_view.py — what compare-vtk.py and compare-vtk-fluid.py both need from VTK: an offscreen
window with one renderer and volfx-bench's camera, and the GL renderer string VTK drew with."""
import vtk


def offscreen_window(ren, width, height, cam, multisamples=None):
    """An offscreen window of width x height showing ren, its camera set from volfx-bench's
    camera dict (eye, center, up, fovy_deg, near, far); multisamples None keeps VTK's default."""
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    if multisamples is not None:
        win.SetMultiSamples(multisamples)
    win.SetSize(width, height)
    win.AddRenderer(ren)
    c = ren.GetActiveCamera()
    c.SetPosition(*cam['eye'])
    c.SetFocalPoint(*cam['center'])
    c.SetViewUp(*cam['up'])
    c.SetViewAngle(cam['fovy_deg'])
    c.SetClippingRange(cam['near'], cam['far'])
    return win


def gl_renderer(win):
    """The OpenGL renderer string of a window that has rendered."""
    return win.ReportCapabilities().split('OpenGL renderer string:')[-1].splitlines()[0].strip()
