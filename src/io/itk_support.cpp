#include "io/itk_support.h"

#include <itkGDCMImageIOFactory.h>
#include <itkMacro.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>
#include <itkObject.h>
#include <itkOutputWindow.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <regex>

#include "lacuna/error.h"

namespace lacuna::io {

namespace {

// Swallows everything ITK would print (warnings about oblique directions, non-uniform DICOM
// spacing, ...). Real failures arrive as exceptions and become lacuna::Error.
class SilentOutputWindow : public itk::OutputWindow {
  public:
    using Self = SilentOutputWindow;
    using Pointer = itk::SmartPointer<Self>;
    itkFactorylessNewMacro(Self);
    itkTypeMacro(SilentOutputWindow, itk::OutputWindow);
    void DisplayText(const char*) override {}

  protected:
    SilentOutputWindow() = default;
};

std::mutex& stderr_mutex() {
    static std::mutex m;
    return m;
}

}  // namespace

void init_itk() {
    static std::once_flag once;
    std::call_once(once, [] {
        // We link the IO modules privately and never include ITK's generated
        // itkImageIOFactoryRegisterManager.h, so nothing registers the factories for us;
        // registering exactly the four we link keeps static and shared ITK builds alike.
        itk::NiftiImageIOFactory::RegisterOneFactory();
        itk::NrrdImageIOFactory::RegisterOneFactory();
        itk::MetaImageIOFactory::RegisterOneFactory();
        itk::GDCMImageIOFactory::RegisterOneFactory();
        itk::Object::GlobalWarningDisplayOff();
        itk::OutputWindow::SetInstance(SilentOutputWindow::New());
    });
}

std::string itk_message(const std::exception& e) {
    const auto* ie = dynamic_cast<const itk::ExceptionObject*>(&e);
    if (!ie) return one_line(e.what());
    std::string d = ie->GetDescription();
    // "itk::ERROR: NrrdImageIO(0x55d0...): " says nothing the caller's prefix does not.
    static const std::regex kClassPrefix(R"(^\s*(itk::ERROR|ITK ERROR): \w+\(0x[0-9a-fA-F]+\): )");
    d = std::regex_replace(d, kClassPrefix, "", std::regex_constants::format_first_only);
    // NrrdIO appends its whole error stack, "[nrrd] nrrdLoad: trouble ... [nrrd] _nrrdFoo:
    // <reason>"; the innermost (last) entry is the actual reason.
    const size_t last = d.rfind("[nrrd] ");
    if (last != std::string::npos) {
        static const std::regex kFunction(R"(^\s*\w+: )");
        std::string inner = std::regex_replace(d.substr(last + 7), kFunction, "",
                                               std::regex_constants::format_first_only);
        if (!inner.empty()) d = "NRRD: " + inner;
    }
    return one_line(d);
}

DiskType disk_type_from_itk(itk::IOComponentEnum c, const std::string& where) {
    using C = itk::IOComponentEnum;
    switch (c) {
        case C::UCHAR:
            return DiskType::U8;
        case C::CHAR:
            return DiskType::I8;
        case C::USHORT:
            return DiskType::U16;
        case C::SHORT:
            return DiskType::I16;
        case C::UINT:
            return DiskType::U32;
        case C::INT:
            return DiskType::I32;
        case C::ULONG:
            return sizeof(unsigned long) == 8 ? DiskType::U64 : DiskType::U32;
        case C::LONG:
            return sizeof(long) == 8 ? DiskType::I64 : DiskType::I32;
        case C::ULONGLONG:
            return DiskType::U64;
        case C::LONGLONG:
            return DiskType::I64;
        case C::FLOAT:
            return DiskType::F32;
        case C::DOUBLE:
            return DiskType::F64;
        case C::LDOUBLE:
            throw Error(where, "voxel type", "long double voxels are not supported");
        default:
            throw Error(where, "voxel type", "unknown voxel component type");
    }
}

itk::IOComponentEnum itk_component_of(VoxelType t) {
    using C = itk::IOComponentEnum;
    switch (t) {
        case VoxelType::UInt8:
            return C::UCHAR;
        case VoxelType::Int16:
            return C::SHORT;
        case VoxelType::UInt16:
            return C::USHORT;
        case VoxelType::Float32:
            return C::FLOAT;
    }
    return C::UCHAR;
}

QuietStderr::QuietStderr() : m_lock(stderr_mutex()) {
    m_saved = std::cerr.rdbuf(m_buffer.rdbuf());
    // C-level stderr too: niftilib fprintf()s "** ERROR: NWAD: wrote only ..." on a short write.
    std::fflush(stderr);
    m_file = std::tmpfile();
    m_saved_fd = m_file ? ::dup(2) : -1;
    if (m_saved_fd >= 0) ::dup2(::fileno(m_file), 2);
}

QuietStderr::~QuietStderr() {
    std::cerr.rdbuf(m_saved);
    std::fflush(stderr);
    if (m_saved_fd >= 0) {
        ::dup2(m_saved_fd, 2);
        ::close(m_saved_fd);
    }
    if (m_file) std::fclose(m_file);
}

std::string QuietStderr::text() const {
    std::string s = m_buffer.str();
    if (m_file && m_saved_fd >= 0) {
        std::fflush(stderr);
        std::rewind(m_file);
        char buf[512];
        size_t n = 0;
        while (s.size() < 4096 && (n = std::fread(buf, 1, sizeof buf, m_file)) > 0)
            s.append(buf, n);
        std::fseek(m_file, 0, SEEK_END);
    }
    return s.empty() ? std::string() : one_line(s, 200);
}

}  // namespace lacuna::io
