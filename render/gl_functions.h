#pragma once
// The OpenGL entry points the renderer uses, as a table of function pointers. libOSMesa and
// libEGL/libGL each export their own gl* symbols, and which one a direct call binds to depends on
// link order, so every call goes through pointers fetched from the back end's own loader.
#include <GL/glcorearb.h>

#include <string>

#include "render/gl_core.h"

namespace isowall {

// X(pointer type, name without the "gl" prefix). One list keeps the members and the loader in
// step.
#define ISOWALL_GL_FUNCTIONS(X)                                    \
    X(PFNGLGETERRORPROC, GetError)                                 \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                           \
    X(PFNGLGETSTRINGPROC, GetString)                               \
    X(PFNGLVIEWPORTPROC, Viewport)                                 \
    X(PFNGLCLEARCOLORPROC, ClearColor)                             \
    X(PFNGLCLEARDEPTHPROC, ClearDepth)                             \
    X(PFNGLCLEARPROC, Clear)                                       \
    X(PFNGLFINISHPROC, Finish)                                     \
    X(PFNGLFLUSHPROC, Flush)                                       \
    X(PFNGLFENCESYNCPROC, FenceSync)                               \
    X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync)                     \
    X(PFNGLDELETESYNCPROC, DeleteSync)                             \
    X(PFNGLENABLEPROC, Enable)                                     \
    X(PFNGLDISABLEPROC, Disable)                                   \
    X(PFNGLDEPTHFUNCPROC, DepthFunc)                               \
    X(PFNGLDEPTHMASKPROC, DepthMask)                               \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                   \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)             \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                   \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)     \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)   \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                 \
    X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)           \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                 \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)           \
    X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                           \
    X(PFNGLREADBUFFERPROC, ReadBuffer)                             \
    X(PFNGLCREATESHADERPROC, CreateShader)                         \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                         \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                       \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                           \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                 \
    X(PFNGLDELETESHADERPROC, DeleteShader)                         \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                       \
    X(PFNGLATTACHSHADERPROC, AttachShader)                         \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                           \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                         \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)               \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                       \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                             \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)             \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                 \
    X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv)                 \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                               \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                   \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)             \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                   \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                             \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                       \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                             \
    X(PFNGLBUFFERDATAPROC, BufferData)                             \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)           \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)   \
    X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray) \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                         \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                           \
    X(PFNGLREADPIXELSPROC, ReadPixels)

struct GlFunctions {
#define ISOWALL_GL_MEMBER(type, name) type name = nullptr;
    ISOWALL_GL_FUNCTIONS(ISOWALL_GL_MEMBER)
#undef ISOWALL_GL_MEMBER

    // Fills every pointer; returns the name of the first entry point the loader lacks, or an
    // empty string when all were found.
    std::string load(GlLoader loader) {
#define ISOWALL_GL_LOAD(type, name)                    \
    name = reinterpret_cast<type>(loader("gl" #name)); \
    if (name == nullptr) return "gl" #name;
        ISOWALL_GL_FUNCTIONS(ISOWALL_GL_LOAD)
#undef ISOWALL_GL_LOAD
        return {};
    }
};

}  // namespace isowall
