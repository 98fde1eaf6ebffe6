// Writes the seeds of fuzz/corpus/nifti and fuzz/corpus/dicom (committed): a small scaled,
// oriented NIfTI-1 through niftilib, and two 8x8 slices cut from the shared DICOM series' headers
// through GDCM, joined as fuzz_dicom reads them. Usage: fuzz_formats_seeds SHARED_SERIES_DIR
// fuzz/corpus
#include <gdcmReader.h>
#include <gdcmWriter.h>
#include <nifti2_io.h>
#include <fstream>
#include <sstream>
#include <string>
int main(int, char** argv) {
    std::string shared = argv[1], out = argv[2];
    // nifti
    const int64_t dims[8] = {3, 4, 4, 3, 1, 1, 1, 1};
    nifti_image* nim = nifti_make_new_nim(dims, DT_INT16, 1);
    for (int i = 0; i < 48; ++i) ((short*)nim->data)[i] = short(i * 7);
    nim->scl_slope = 2;
    nim->scl_inter = -10;
    nim->sform_code = 1;
    nim->sto_xyz.m[0][0] = -1;
    nim->sto_xyz.m[1][1] = 1;
    nim->sto_xyz.m[2][2] = 2;
    nifti_set_filenames(nim, (out + "/nifti/small.nii").c_str(), 0, 1);
    nifti_image_write(nim);
    nifti_image_free(nim);
    // dicom: two 8x8 slices from the shared series' headers
    std::string joined;
    for (int k = 1; k <= 2; ++k) {
        gdcm::Reader r;
        r.SetFileName((shared + "/1-00" + std::to_string(k) + ".dcm").c_str());
        if (!r.Read()) return 1;
        gdcm::DataSet& ds = r.GetFile().GetDataSet();
        unsigned short n = 8;
        gdcm::DataElement rows(gdcm::Tag(0x28, 0x10));
        rows.SetByteValue((char*)&n, 2);
        ds.Replace(rows);
        gdcm::DataElement cols(gdcm::Tag(0x28, 0x11));
        cols.SetByteValue((char*)&n, 2);
        ds.Replace(cols);
        std::string px(128, '\0');
        for (int i = 0; i < 128; ++i) px[i] = char(i * k);
        gdcm::DataElement pd(gdcm::Tag(0x7fe0, 0x10));
        pd.SetVR(gdcm::VR::OW);
        pd.SetByteValue(px.data(), 128);
        ds.Replace(pd);
        std::ostringstream os;
        gdcm::Writer w;
        w.SetStream(os);
        w.SetFile(r.GetFile());
        if (!w.Write()) return 2;
        joined += (k > 1 ? "\n@next.dcm\n" : "") + os.str();
    }
    std::ofstream(out + "/dicom/two_slices.bin", std::ios::binary) << joined;
}
