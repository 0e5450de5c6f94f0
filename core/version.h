/* version.h: the renderer's version, written into every EXR it produces. */
#ifndef RT_VERSION_H
#define RT_VERSION_H
#define RTSPHERES_VERSION "0.1.0"
#endif
