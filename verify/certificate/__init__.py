"""The certificate artefact: what :func:`certify` issues and people hand on.

:mod:`~verify.certificate.certify` runs the theorem's pipeline and returns a :class:`Certificate`;
its views are the JSON form (:mod:`~verify.certificate.jsonio`), the hand-off to the loop
(:mod:`~verify.certificate.handoff`) and the text report (:mod:`~verify.certificate.report`).
"""

from verify.certificate.certify import (ASSUMPTIONS, PREMISES, THEOREM, Certificate, Condition, NotCertifiedError,
                                        certify)

__all__ = ["ASSUMPTIONS", "PREMISES", "THEOREM", "Certificate", "Condition", "NotCertifiedError", "certify"]
