"""What each patent lens of the bundled library states about itself, as its transcription gives it.

The numbers are the patents' own first-order data as Bill Claff's OpticalBench transcriptions print
them in their ``[variable distances]`` table (BeamFour/Beam42, Examples/jfotoptix/..., commit
d6aabe24116e): focal length, F-number, the back focus (the last gap of the prescription: where the
table's ``Bf`` counts through a cover glass, the gap after it), and at the close-focus column the
magnification and, where given, the object-to-image distance ``S``; ``total``: the table's
``Total Length``, first vertex to image at infinity focus. They were typed from those
files, not from physcam's output. Master Prime f-numbers: the patent gives none; 1.24 is the
transcription's figure (its note says so).
"""

#: slug -> efl (mm), fno, bf (mm), close_mag, close_s (mm, object to image), total (mm), cine, transcription file
PATENT_STATED = {
    "arri_zeiss_master_prime_50mm": dict(efl=49.99, fno=1.24, bf=36.004, cine=True,
                                         file="ARRI-zeiss-master-prime/US20070236805_Example01.txt"),
    "arri_zeiss_master_prime_75mm": dict(efl=74.98, fno=1.24, bf=36.153, cine=True,
                                         file="ARRI-zeiss-master-prime/US20070236805_Example03.txt"),
    "arri_zeiss_master_prime_100mm": dict(efl=99.80, fno=1.24, bf=40.123, close_mag=-0.112, cine=True,
                                          file="ARRI-zeiss-master-prime/US20070236805_Example04.txt"),
    "arri_signature_prime_58mm_ex1": dict(efl=57.99, fno=1.70, bf=1.00, close_mag=-0.18705, cine=True,
                                          file="ARRI-signature-prime-58mm/US20200341250_Example01.txt"),
    "arri_signature_prime_58mm_ex2": dict(efl=57.99, fno=1.70, bf=1.00, close_mag=-0.18705, cine=True,
                                          file="ARRI-signature-prime-58mm/US20200341250_Example02.txt"),
    "canon_rf_50mm_f1_2": dict(efl=51.10, fno=1.25, bf=14.60, close_mag=-0.19, close_s=400.0, total=111.01,
                               file="canon-rf50mm-f1.2L/canon-rf-50mmf1.2.txt"),
    "sigma_40mm_f1_4_art": dict(efl=41.20, fno=1.45, bf=39.0002, close_mag=-0.164, close_s=393.0, total=171.00,
                                file="sigma-40mm-f1.4/JP2020-012952_Example01.txt"),
    "nikkor_z_58mm_f0_95_noct": dict(efl=59.62, fno=0.98, bf=1.0, total=160.74, file="nikkor-58mm-z-f0.95/nikkor-z-58mmf0.95_ex1.txt"),
    "nikkor_28mm_f1_4e": dict(efl=28.41, fno=1.45, bf=38.47, close_mag=-0.219, total=144.38, file="nikkor-28mm-f1.4e/nikkor-28mmf1.4-afs.txt"),
    "sigma_28mm_f1_4_art": dict(efl=28.70, fno=1.46, bf=1.0, close_mag=-0.025, close_s=1275.0, total=152.51,
                                file="sigma-28mm-f1.4/JP2019-219472_Example06P.txt"),
    "sony_zeiss_55mm_f1_8_za": dict(efl=53.61, fno=1.86, bf=1.0, close_mag=-0.03333,
                                    file="sony-zeiss-55mm-f1.8-za/US20150092100_Example01.txt"),
    "sigma_50mm_f1_4_art": dict(efl=49.58, fno=1.46, bf=38.7999, close_mag=-0.1779, total=142.0,
                                file="sigma-50mm-f1.4-art/JP2015-114366_Example01.txt"),
}
